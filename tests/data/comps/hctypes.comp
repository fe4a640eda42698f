component hctypes "Every HAL type as pins and params, with the default spellings";
pin in bit b_in = TRUE;
pin in float f_in = .5;
pin in s32 s_in = -16;
pin in u32 u_in = 0x10;
pin in signed sg_in = 7;
pin in unsigned us_in = 1e3;
pin out bit b_out;
pin out float f_out;
pin out s32 s_out;
pin out u32 u_out;
pin out signed sg_out;
pin out unsigned us_out;
param rw float big = 1e20;
param rw bit flag = FALSE;
param r s32 calls;
function _;
license "GPL";
;;
FUNCTION(_) {
    b_out = !b_in ^ flag;
    f_out = f_in * 2 + (big > 1e19 ? 1 : 0);
    s_out = s_in - 1;
    u_out = u_in + 1;
    sg_out = -sg_in;
    us_out = us_in / 2;
    calls++;
}
