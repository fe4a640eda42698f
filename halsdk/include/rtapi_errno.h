/* rtapi_errno.h - errno values returned (negated) by HAL and RTAPI calls */
#ifndef RTAPI_ERRNO_H
#define RTAPI_ERRNO_H
#include <errno.h>
#endif
