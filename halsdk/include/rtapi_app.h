/*
 * rtapi_app.h - module entry points and module parameters.
 *
 * A C component defines rtapi_app_main() (called by loadrt after its
 * module parameters are set) and rtapi_app_exit() (called by unloadrt).
 * Module parameters are declared with the RTAPI_MP_* macros; each one
 * registers itself, at load time, in the table of its module that the
 * halsdk loader reads.
 */
#ifndef RTAPI_APP_H
#define RTAPI_APP_H

#include "rtapi.h"
#include "halsdk_module.h"

#ifdef __cplusplus
extern "C" {
#endif

int rtapi_app_main(void);
void rtapi_app_exit(void);

#define HALSDK_MP_(var, kind, count, desc)                                 \
    static void __attribute__((constructor)) halsdk_mp_reg_##var(void)     \
    {                                                                      \
        halsdk_modparam_register(#var, kind, (void *)&(var), count, desc); \
    }

#define RTAPI_MP_INT(var, desc) HALSDK_MP_(var, 'i', 1, desc)
#define RTAPI_MP_LONG(var, desc) HALSDK_MP_(var, 'l', 1, desc)
#define RTAPI_MP_STRING(var, desc) HALSDK_MP_(var, 's', 1, desc)
#define RTAPI_MP_ARRAY_INT(var, num, desc) HALSDK_MP_(var, 'I', num, desc)
#define RTAPI_MP_ARRAY_LONG(var, num, desc) HALSDK_MP_(var, 'L', num, desc)
#define RTAPI_MP_ARRAY_STRING(var, num, desc) HALSDK_MP_(var, 'S', num, desc)

/* module information: each use makes its own (unused) string, so a
   comp may repeat in its code section what halcompile writes for its
   author, description and license declarations */
#define HALSDK_CAT2_(a, b) a##b
#define HALSDK_CAT_(a, b) HALSDK_CAT2_(a, b)
#define HALSDK_MODINFO_(tag, s)                                           \
    __attribute__((used)) static const char                               \
        HALSDK_CAT_(halsdk_##tag##_, __COUNTER__)[] = s
#define MODULE_LICENSE(s) HALSDK_MODINFO_(license, s)
#define MODULE_AUTHOR(s) HALSDK_MODINFO_(author, s)
#define MODULE_DESCRIPTION(s) HALSDK_MODINFO_(description, s)
#define MODULE_INFO(tag, s)
/* offer sym (a function or variable of this module) to the modules
   loaded after it; they find it with halsdk_symbol_find("sym") */
#define EXPORT_SYMBOL(sym)                                                 \
    static void __attribute__((constructor)) halsdk_sym_reg_##sym(void)    \
    {                                                                      \
        halsdk_symbol_register(#sym, (void *)&(sym));                      \
    }
#define EXPORT_SYMBOL_GPL(sym) EXPORT_SYMBOL(sym)

/* the address a loaded module exported as name, or NULL; records that
   this module uses that one (which then cannot be unloaded first) */
#define halsdk_symbol_find(name) \
    (HALSDK_API->symbol_find((name), halsdk_module_name))

#ifdef __cplusplus
}
#endif

#endif /* RTAPI_APP_H */
