component hcperiod "period and fperiod in two functions, fp and nofp";
pin out s32 nperiod;
pin out float fsec;
pin out u32 ticks;
function count_ns nofp;
function secs fp;
license "GPL";
;;
FUNCTION(count_ns) {
    nperiod = period;
    ticks++;
}

FUNCTION(secs) {
    fsec += fperiod;
}
