/* rtapi_stdint.h - fixed-size integer names of RTAPI code */
#ifndef RTAPI_STDINT_H
#define RTAPI_STDINT_H
#include <stdint.h>
#include <inttypes.h>
typedef int8_t rtapi_s8;
typedef int16_t rtapi_s16;
typedef int32_t rtapi_s32;
typedef int64_t rtapi_s64;
typedef uint8_t rtapi_u8;
typedef uint16_t rtapi_u16;
typedef uint32_t rtapi_u32;
typedef uint64_t rtapi_u64;
typedef intptr_t rtapi_intptr_t;
typedef uintptr_t rtapi_uintptr_t;
#endif
