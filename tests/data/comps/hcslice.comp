component hcslice "Split an unsigned value into bits";
pin in u32 in;
pin out bit out-##[32 : personality] "bit N of in";
function _ nofp;
option default_personality 8;
license "GPL";
;;
int i;
for (i = 0; i < personality; i++)
    out(i) = (in >> i) & 1;
