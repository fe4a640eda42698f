/* rtapi_gfp.h - allocation flags of rtapi_kmalloc (ignored in userspace) */
#ifndef RTAPI_GFP_H
#define RTAPI_GFP_H
typedef unsigned rtapi_gfp_t;
#define RTAPI_GFP_KERNEL 0u
#define RTAPI_GFP_ATOMIC 1u
#define RTAPI_GFP_DMA 2u
#endif
