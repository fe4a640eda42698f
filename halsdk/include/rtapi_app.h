/*
 * rtapi_app.h - the entry points of a realtime module.
 *
 * A C component defines rtapi_app_main() (called by loadrt after its
 * module parameters are set; 0 on success, a negative errno otherwise)
 * and, optionally, rtapi_app_exit() (called by unloadrt, and only after
 * a successful rtapi_app_main()).  The module information and parameter
 * macros (MODULE_LICENSE, RTAPI_MP_INT, EXPORT_SYMBOL, ...) are in
 * rtapi.h, as in the reference.
 */
#ifndef RTAPI_APP_H
#define RTAPI_APP_H

#include "rtapi.h"

RTAPI_BEGIN_DECLS

int rtapi_app_main(void);
void rtapi_app_exit(void);

RTAPI_END_DECLS

#endif /* RTAPI_APP_H */
