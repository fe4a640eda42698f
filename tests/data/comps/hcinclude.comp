component hcinclude "include declarations with angle brackets and quotes";
include <rtapi_math.h>;
include "rtapi_string.h";
pin in float x;
pin out float root;
pin out float mag;
pin out s32 len;
function _;
license "GPL";
;;
FUNCTION(_) {
    root = sqrt(fabs(x));
    mag = fabs(x);
    len = (int)strlen("hal");
}
