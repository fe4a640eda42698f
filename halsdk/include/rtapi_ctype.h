/* rtapi_ctype.h - character classes for realtime code */
#ifndef RTAPI_CTYPE_H
#define RTAPI_CTYPE_H
#include <ctype.h>
#endif
