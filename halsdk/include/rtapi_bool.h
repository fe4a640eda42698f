/* rtapi_bool.h - bool for C and C++ RTAPI code */
#ifndef RTAPI_BOOL_H
#define RTAPI_BOOL_H
#ifndef __cplusplus
#include <stdbool.h>
#endif
#endif
