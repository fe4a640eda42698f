component hcsingle "A singleton with helpers named like libc";
pin out s32 value;
pin in s32 in;
function _ nofp;
option singleton yes;
license "GPL";
;;
/* file-scope helpers and mutable globals of the code section */
int shared_total;
static int read(int x) { return x * 2; }
#define TWICE(x) read(x)

FUNCTION(_) {
    shared_total += in;
    value = TWICE(shared_total);
}
