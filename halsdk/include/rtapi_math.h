/* rtapi_math.h - the math library for realtime code */
#ifndef RTAPI_MATH_H
#define RTAPI_MATH_H

#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "rtapi.h"
#include "rtapi_byteorder.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#ifndef M_PIl
#define M_PIl 3.141592653589793238462643383279502884L
#endif
#ifndef M_PI_2l
#define M_PI_2l 1.570796326794896619231321691639751442L
#endif

/* the fields of an IEEE 754 double, in this machine's order */
union ieee754_double {
    double d;
    struct {
#if RTAPI_BIG_ENDIAN
        unsigned int negative:1;
        unsigned int exponent:11;
        unsigned int mantissa0:20;
        unsigned int mantissa1:32;
#else
        unsigned int mantissa1:32;
        unsigned int mantissa0:20;
        unsigned int exponent:11;
        unsigned int negative:1;
#endif
    } ieee;
};
#define IEEE754_DOUBLE_BIAS 0x3ff

#endif
