/*
 * hal_symbol.c - symbols that realtime modules offer each other.
 *
 * A module exports a name and an address (EXPORT_SYMBOL); another module
 * of the same host process finds it by name (motmod finds the kinematics
 * functions, the homing and trajectory planner tables).  A find records
 * the pair (user, exporter) so that the exporter cannot be unloaded
 * while its user is loaded.  Only load and unload touch the registry,
 * never a realtime thread, so a mutex is fine here.
 */
#define _GNU_SOURCE
#include "hal_core.h"

#include <errno.h>
#include <pthread.h>
#include <string.h>

#define MAX_SYMBOLS 256
#define MAX_USES 256
#define MODNAME_LEN 64

typedef struct {
    char name[HAL_NAME_SIZE];
    char module[MODNAME_LEN];
    void *addr;
} symbol_t;

typedef struct {
    char user[MODNAME_LEN];
    char exporter[MODNAME_LEN];
} use_t;

static symbol_t symbols[MAX_SYMBOLS];
static int nsymbols;
static use_t uses[MAX_USES];
static int nuses;
static pthread_mutex_t registry_lock = PTHREAD_MUTEX_INITIALIZER;

static symbol_t *lookup(const char *name)
{
    for (int i = 0; i < nsymbols; i++)
        if (strcmp(symbols[i].name, name) == 0)
            return &symbols[i];
    return NULL;
}

int hal_symbol_export(const char *name, void *addr, const char *module)
{
    if (!name || !*name || strlen(name) >= HAL_NAME_SIZE)
        return hal_fail(EINVAL, "symbol name '%s' is empty or too long",
                        name ? name : "");
    if (!module || !*module || strlen(module) >= MODNAME_LEN)
        return hal_fail(EINVAL, "symbol '%s': bad module name", name);
    pthread_mutex_lock(&registry_lock);
    int r = 0;
    symbol_t *s = lookup(name);
    if (s)
        r = hal_fail(EEXIST, "symbol '%s' is already exported by module "
                     "'%s'", name, s->module);
    else if (nsymbols >= MAX_SYMBOLS)
        r = hal_fail(ENOSPC, "symbol '%s': more than %d exported symbols",
                     name, MAX_SYMBOLS);
    else {
        s = &symbols[nsymbols++];
        strcpy(s->name, name);
        strcpy(s->module, module);
        s->addr = addr;
    }
    pthread_mutex_unlock(&registry_lock);
    return r;
}

void *hal_symbol_find(const char *name, const char *user)
{
    if (!name)
        return NULL;
    pthread_mutex_lock(&registry_lock);
    symbol_t *s = lookup(name);
    void *addr = s ? s->addr : NULL;
    if (s && user && *user && strlen(user) < MODNAME_LEN &&
        strcmp(user, s->module) != 0) {
        int known = 0;
        for (int i = 0; i < nuses && !known; i++)
            known = strcmp(uses[i].user, user) == 0 &&
                    strcmp(uses[i].exporter, s->module) == 0;
        if (!known && nuses < MAX_USES) {
            strcpy(uses[nuses].user, user);
            strcpy(uses[nuses].exporter, s->module);
            nuses++;
        }
    }
    pthread_mutex_unlock(&registry_lock);
    return addr;
}

/* remove the symbols a module exported and the uses it recorded */
void hal_symbol_drop(const char *module)
{
    if (!module)
        return;
    pthread_mutex_lock(&registry_lock);
    int k = 0;
    for (int i = 0; i < nsymbols; i++)
        if (strcmp(symbols[i].module, module) != 0)
            symbols[k++] = symbols[i];
    nsymbols = k;
    k = 0;
    for (int i = 0; i < nuses; i++)
        if (strcmp(uses[i].user, module) != 0)
            uses[k++] = uses[i];
    nuses = k;
    pthread_mutex_unlock(&registry_lock);
}

/* a loaded module that uses symbols of module, or NULL */
const char *hal_symbol_user(const char *module)
{
    static __thread char user[MODNAME_LEN];
    const char *ret = NULL;
    if (!module)
        return NULL;
    pthread_mutex_lock(&registry_lock);
    for (int i = 0; i < nuses && !ret; i++)
        if (strcmp(uses[i].exporter, module) == 0) {
            strcpy(user, uses[i].user);
            ret = user;
        }
    pthread_mutex_unlock(&registry_lock);
    return ret;
}
