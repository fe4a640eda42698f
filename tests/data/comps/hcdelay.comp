component hcdelay "Delay the rising and falling edges of a bit";
pin in bit in;
pin out bit out;
pin out float elapsed "seconds since in and out differ";
param rw float on-delay = 0.5 "seconds before out follows a rising in";
param rw float off-delay = 0.5 "seconds before out follows a falling in";
variable double timer;
function _ fp;
license "GPL";
;;
int want = in;
if (want == out) {
    timer = 0;
} else {
    timer += fperiod;
    if (timer >= (want ? on_delay : off_delay)) {
        out = want;
        timer = 0;
    }
}
elapsed = timer;
