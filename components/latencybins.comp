component latencybins "Histogram of thread scheduling latency, for a latency test script";

description """
Each time it runs, the component reads the clock (rtapi_get_time) and
computes the latency: the time since its previous run minus the thread
period, in ns. It sorts the latencies into bins of \\fBnsbinsize\\fR ns
and keeps their minimum, maximum and variance. A script (the reference's
latency-histogram) reads the bins one at a time through \\fBindex\\fR.
Only the realtime component is provided here, not that script.

Use:
.IP \\(bu 2
read \\fBavailablebins\\fR (1000): the largest possible
\\fBmaxbinnumber\\fR;
.IP \\(bu 2
set \\fBmaxbinnumber\\fR to \\fIN\\fR (at most availablebins): the bins
are numbered \\-\\fIN\\fR to +\\fIN\\fR. A latency L goes into bin L /
nsbinsize, rounded towards zero, so bin 0 holds the latencies from
\\-(nsbinsize\\-1) to nsbinsize\\-1 and bin \\-0 stays empty;
latencies beyond the last bins are counted in \\fBpextra\\fR and
\\fBnextra\\fR;
.IP \\(bu 2
set \\fBnsbinsize\\fR; nothing is measured while it is 0 or negative;
.IP \\(bu 2
for each \\fIi\\fR from 0 to \\fIN\\fR: set \\fBindex\\fR to \\fIi\\fR,
wait until \\fBcheck\\fR equals \\fIi\\fR, then read \\fBpbinvalue\\fR (bin
+\\fIi\\fR) and \\fBnbinvalue\\fR (bin \\-\\fIi\\fR). An index below 0 or
above maxbinnumber reads \\-1.
.PP
The first run after loading only reads the clock. While \\fBreset\\fR is
TRUE, the bins, extra counts, latency, latency-max and latency-min are
cleared (latency-max to the lowest s32 value, latency-min to the
highest) and the variance starts over; the clock keeps being read, so
the run after the reset measures again.
""";

pin in s32 maxbinnumber = 1000 "Number of bins on each side of bin 0 (at most availablebins)";
pin in s32 index "Number of the bin pair to read, 0 to maxbinnumber";
pin in bit reset "While TRUE, clear the histogram and the statistics";
pin in s32 nsbinsize "Width of a bin, in ns; no measurement while 0 or negative";
pin out s32 check "Copy of index, showing that the outputs belong to it";
pin out s32 latency "Latency of this run: time since the previous run minus the period, in ns";
pin out s32 latency_max "Largest latency since the last reset, in ns";
pin out s32 latency_min "Smallest (most negative) latency since the last reset, in ns";
pin out s32 pbinvalue "Count of bin +index (\\-1 for an index out of range)";
pin out s32 nbinvalue "Count of bin \\-index (\\-1 for an index out of range)";
pin out s32 pextra "Count of latencies above the last positive bin";
pin out s32 nextra "Count of latencies below the last negative bin";
pin out s32 variance "Sample variance of the latencies since the last reset, in ns squared (integer arithmetic; kept while fewer than two latencies were measured)";
pin out s32 availablebins = 1000 "Number of bins available on each side";

function _ nofp "Measure the latency and update the histogram";

variable rtapi_s32 pbins[1001];
variable rtapi_s32 nbins[1001];
variable rtapi_s32 pextras;
variable rtapi_s32 nextras;
variable rtapi_s64 last_ns;
variable int have_last;
variable int cleared;
variable rtapi_s64 samples;
variable rtapi_s64 sum;
variable rtapi_s64 sum_sq;

see_also "timedelta(9)";
author "the halsdk authors";
license "GPL";
;;
#define AVAILABLE 1000

static void clear_stats(struct __comp_state *__comp_inst)
{
    int i;

    for (i = 0; i <= AVAILABLE; i++) {
        pbins[i] = 0;
        nbins[i] = 0;
    }
    pextras = 0;
    nextras = 0;
    samples = 0;
    sum = 0;
    sum_sq = 0;
    latency = 0;
    latency_max = INT32_MIN;
    latency_min = INT32_MAX;
}

FUNCTION(_) {
    rtapi_s64 now = rtapi_get_time();
    int top = maxbinnumber;

    if (top > AVAILABLE)
        top = AVAILABLE;
    if (!cleared || reset) {
        clear_stats(__comp_inst);
        cleared = 1;
    } else if (have_last && nsbinsize > 0) {
        rtapi_s32 lat = (rtapi_s32)(now - last_ns - period);
        rtapi_s32 bin = lat / nsbinsize;

        latency = lat;
        if (lat > latency_max)
            latency_max = lat;
        if (lat < latency_min)
            latency_min = lat;
        if (bin > top)
            pextras++;
        else if (bin < -top)
            nextras++;
        else if (bin >= 0)
            pbins[bin]++;
        else
            nbins[-bin]++;
        samples++;
        sum += lat;
        sum_sq += (rtapi_s64)lat * lat;
        if (samples > 1)
            variance = (sum_sq - sum * sum / samples) / (samples - 1);
    }
    last_ns = now;
    have_last = 1;

    pextra = pextras;
    nextra = nextras;
    check = index;
    if (index < 0 || index > maxbinnumber || index > AVAILABLE) {
        pbinvalue = -1;
        nbinvalue = -1;
    } else {
        pbinvalue = pbins[index];
        nbinvalue = nbins[index];
    }
}
