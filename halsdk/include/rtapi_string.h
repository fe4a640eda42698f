/* rtapi_string.h - string functions usable in realtime code */
#ifndef RTAPI_STRING_H
#define RTAPI_STRING_H
#include <string.h>
#include <stdlib.h>
#endif
