component hcvars "Variables: scalars, arrays, pointers and defaults";
pin out float avg;
pin out s32 filled;
pin out s32 pval;
pin in float in;
variable double hist[4];
variable int pos = 0;
variable int n;
variable int *cell;
variable double decay = 0.5;
option extra_setup yes;
function _;
license "GPL";
;;
EXTRA_SETUP() {
    cell = hal_malloc(sizeof(int));
    if (!cell)
        return -ENOMEM;
    *cell = 40 + extra_arg;
    return 0;
}

FUNCTION(_) {
    int i;
    double s = 0;
    hist[pos] = in;
    pos = (pos + 1) % 4;
    if (n < 4) n++;
    for (i = 0; i < n; i++)
        s += hist[i];
    avg = s / n * decay * 2;
    filled = n;
    *cell += 1;
    pval = *cell;
}
