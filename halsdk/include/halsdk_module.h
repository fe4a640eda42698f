/*
 * halsdk_module.h - the table of module parameters of a C component.
 *
 * Filled by the RTAPI_MP_* constructors when the module is loaded; read by
 * the module's Python entry (halsdk/core/src/c_module.c) to apply the
 * parameters of a loadrt line before rtapi_app_main() runs.
 */
#ifndef HALSDK_MODULE_H
#define HALSDK_MODULE_H

#ifdef __cplusplus
extern "C" {
#endif

#define HALSDK_MAX_MODPARAMS 64

typedef struct {
    const char *name;
    char kind;          /* i l s: int, long, string; I L S: arrays */
    void *addr;
    int count;          /* elements, for arrays */
    const char *desc;
} halsdk_modparam_t;

__attribute__((visibility("hidden")))
void halsdk_modparam_register(const char *name, char kind, void *addr,
                              int count, const char *desc);

/* EXPORT_SYMBOL: the table of symbols the module offers other modules,
   filled by constructors like the modparams and exported by the module
   entry when the module loads */
__attribute__((visibility("hidden")))
void halsdk_symbol_register(const char *name, void *addr);

/* the module's name (HALSDK_MODULE_NAME), defined by the module entry */
__attribute__((visibility("hidden")))
extern const char halsdk_module_name[];

#ifdef __cplusplus
}
#endif

#endif /* HALSDK_MODULE_H */
