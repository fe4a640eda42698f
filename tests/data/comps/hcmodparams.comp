component hcmodparams "RTAPI_MP_* module parameters declared in the code section, and dummy modparams";
pin out s32 ival;
pin out s32 lval;
pin out s32 slen;
pin out s32 asum;
modparam dummy scale "documented here, declared with RTAPI_MP_INT below";
modparam dummy arr "documented here, declared with RTAPI_MP_ARRAY_INT below";
modparam int direct = 4 "a modparam declared in the declarations";
function _ nofp;
option singleton yes;
license "GPL";
;;
#include <rtapi_string.h>
static int scale = 7;
RTAPI_MP_INT(scale, "an int");
static long lv = 11;
RTAPI_MP_LONG(lv, "a long");
static char *word = "abcd";
RTAPI_MP_STRING(word, "a string");
static int arr[4] = {1, 2, 3, 4};
RTAPI_MP_ARRAY_INT(arr, 4, "an array");

FUNCTION(_) {
    int i, s = 0;
    for (i = 0; i < 4; i++)
        s += arr[i];
    ival = scale + direct;
    lval = (int)lv;
    slen = word ? (int)strlen(word) : -1;
    asum = s;
}
