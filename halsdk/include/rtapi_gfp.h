/* rtapi_gfp.h - allocation flags of rtapi_kmalloc (ignored in userspace;
   names and values as the reference's user-space build has them) */
#ifndef RTAPI_GFP_H
#define RTAPI_GFP_H
enum rtapi_gfp_e {
    RTAPI_GFP_BUFFER,
    RTAPI_GFP_ATOMIC,
    RTAPI_GFP_KERNEL,
    RTAPI_GFP_USER,
    RTAPI_GFP_NOBUFFER,
    RTAPI_GFP_NFS,
    RTAPI_GFP_DMA
};
typedef unsigned long rtapi_gfp_t;
#endif
