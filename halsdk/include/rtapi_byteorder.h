/* rtapi_byteorder.h - the byte order of this machine, as 0/1 values */
#ifndef RTAPI_BYTEORDER_H
#define RTAPI_BYTEORDER_H
#include <endian.h>
#define RTAPI_BIG_ENDIAN (__BYTE_ORDER == __BIG_ENDIAN)
#define RTAPI_LITTLE_ENDIAN (__BYTE_ORDER == __LITTLE_ENDIAN)
#define RTAPI_FLOAT_BIG_ENDIAN (__FLOAT_WORD_ORDER == __BIG_ENDIAN)
#endif
