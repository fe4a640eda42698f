/* arrays, all pin types, defaults and two functions */
component hcarrays "Arrays and defaults";
pin in float in-#[4] "inputs";
pin out float sum = -1.5;
pin out s32 idx.##.v[3] = 7;
pin io u32 count_ = 0x10 "an io pin";
pin out s64 big = -5000000000;
pin out u64 ubig = 0xFFFFFFFFFFFF;
pin out bit flag = TRUE;
pin in float in_ "in is a C name for a pin named in";
param rw float gain-#[4] = 1.0;
param r float big_param = 1e20;
param rw float half = .5;
param r s32 calls;
variable double hist[4] = 2.5;
variable int *unused_ptr;
variable unsigned int ticks;
function _ fp "sum the inputs";
function count_calls nofp;
license "GPL";
;;
FUNCTION(_) {
    int i;
    double s = 0;
    for (i = 0; i < 4; i++) {
        s += in(i) * gain(i);
        hist[i] = in(i);
    }
    sum = s + in_;
    for (i = 0; i < 3; i++) idx_v(i) = idx_v(i) + 1;
    big = big - 1;
    ubig = ubig + 1;
    flag = !flag;
    count_ = count_ + 1;
}

FUNCTION(count_calls) {
    ticks++;
    calls = ticks;
}
