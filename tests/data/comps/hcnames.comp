component hcnames "C names that are keywords elsewhere or shadow libc";
pin in s32 in;
pin in bit and;
pin in bit or;
pin out s32 index;
pin out s32 select;
pin out s32 open;
pin out s32 in##-copy[2];
param rw s32 y0 = 3;
function read nofp;
function write nofp;
license "GPL";
;;
#include <stdlib.h>
#include <string.h>
#include <rtapi_math.h>

static int twice(int x) { return 2 * x; }

FUNCTION(read) {
    index = in;
    select = (and && or) ? 1 : 0;
}

FUNCTION(write) {
    open = twice(index) + y0;
    in_copy(0) = (int)strlen("abc");
    in_copy(1) = abs(-4);
}
