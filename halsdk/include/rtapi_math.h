/* rtapi_math.h - the math library for realtime code */
#ifndef RTAPI_MATH_H
#define RTAPI_MATH_H
#include <math.h>
#include <stdlib.h>
#endif
