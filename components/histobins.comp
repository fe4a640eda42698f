component histobins "Histogram of a signal, read back one bin at a time (the realtime half of hal-histogram)";

description """
Counts how often an input signal falls into each of \\fBnbins\\fR equal bins
and keeps running statistics of it. A userspace program (such as the
reference's hal-histogram script) reads the histogram back through pins,
one bin a cycle:

.IP 1. 4
Read \\fBavailablebins\\fR (200): the most bins there are.
.IP 2. 4
Set \\fBminvalue\\fR, \\fBbinsize\\fR and \\fBnbins\\fR (1 to availablebins).
Bin \\fIi\\fR (0 to nbins\\-1) counts inputs from minvalue + i*binsize up to
(not including) minvalue + (i+1)*binsize.
.IP 3. 4
Set \\fBindex\\fR to a bin number, wait until \\fBcheck\\fR equals it, then
read \\fBbinvalue\\fR (that bin's count), \\fBpextra\\fR (inputs above
minvalue + nbins*binsize) and \\fBnextra\\fR (inputs below minvalue).
.PP
\\fBpintype\\fR picks the input: 0 \\fBinput\\fR, 1 \\fBinput-s32\\fR,
2 \\fBinput-u32\\fR, 3 \\fBinput-bit\\fR (other values also use \\fBinput\\fR).

Each cycle one sample is taken. The first cycle after loading, after
\\fBreset\\fR, or after \\fBnbins\\fR, \\fBbinsize\\fR or \\fBminvalue\\fR changed
starts afresh: the bins, counts and statistics are cleared, \\fBnsamples\\fR
becomes 1 and \\fBinput-min\\fR and \\fBinput-max\\fR take the input, but that
sample is not put in a bin and counts as 0 in \\fBmean\\fR and
\\fBvariance\\fR (as in the reference).

With \\fBnbins\\fR out of range \\fBinput-error\\fR is TRUE and nothing but
\\fBcheck\\fR is updated until it is valid again.
""";

pin in u32 pintype "Which input to sample: 0 input, 1 input-s32, 2 input-u32, 3 input-bit";
pin in float input "The input when pintype is 0";
pin in s32 input_s32 "The input when pintype is 1";
pin in u32 input_u32 "The input when pintype is 2";
pin in bit input_bit "The input when pintype is 3 (counts as 0 or 1)";

pin in u32 nbins = 20 "Number of bins, 1 to availablebins; a change restarts the histogram";
pin in float binsize = 1 "Width of each bin; a change restarts the histogram";
pin in float minvalue = 0 "Lower edge of bin 0; a change restarts the histogram";

pin in s32 index "The bin to read out on binvalue";
pin out s32 check "Follows index: binvalue belongs to this bin";
pin in bit reset "While TRUE, the histogram and statistics restart every cycle";
pin in bit method "FALSE: running (Welford) mean and variance; TRUE: from sums of the samples taken while TRUE";
pin out bit input_error "TRUE while nbins is 0 or more than availablebins; only check is updated then";

pin out float binvalue "Count of the bin selected by index, -1 when index is not a bin";
pin out float pextra "Count of the inputs above the last bin";
pin out float nextra "Count of the inputs below minvalue";
pin out float input_min "Smallest input since the start";
pin out float input_max "Largest input since the start";
pin out u32 nsamples "Number of cycles since the start (the starting one included)";
pin out float variance "Sample variance of the inputs";
pin out float mean "Mean of the inputs";
pin out s32 availablebins = 200 "Most bins there are (nbins may not exceed it)";

variable int started;
variable unsigned last_nbins;
variable double last_binsize;
variable double last_minvalue;
variable double m2;
variable double sum;
variable double sumsq;
variable double bins[201];

function _ "Take one sample and update the outputs";

author "the halsdk authors";
license "GPL";
;;
#define MAXBINS 200

FUNCTION(_) {
    double x, maxv;
    int n, k;

    check = index;
    if (nbins < 1 || nbins > MAXBINS) {
        /* everything else holds until nbins is valid again */
        input_error = 1;
        return;
    }
    input_error = 0;

    switch (pintype) {
    case 1: x = input_s32; break;
    case 2: x = input_u32; break;
    case 3: x = input_bit ? 1.0 : 0.0; break;
    default: x = input; break;
    }

    if (!started || reset || nbins != last_nbins
        || binsize != last_binsize || minvalue != last_minvalue) {
        /* start afresh; this sample only sets the extremes */
        started = 1;
        last_nbins = nbins;
        last_binsize = binsize;
        last_minvalue = minvalue;
        for (k = 0; k <= MAXBINS; k++)
            bins[k] = 0;
        pextra = nextra = 0;
        /* the extremes start from +-1e99, as in LinuxCNC (an infinite,
           NaN or huger sample does not replace both) */
        input_min = 1e99;
        input_max = -1e99;
        if (x < input_min)
            input_min = x;
        if (x > input_max)
            input_max = x;
        nsamples = 1;
        mean = variance = 0;
        m2 = sum = sumsq = 0;
    } else {
        double b;

        maxv = minvalue + nbins * binsize;
        if (x < minvalue) {
            nextra += 1;
        } else if (x > maxv) {
            pextra += 1;
        } else {
            /* x == maxv lands one past the last bin, which is not shown */
            b = (x - minvalue) / binsize;
            if (b >= 0 && b < MAXBINS + 1)
                bins[(int)b] += 1;
        }
        if (x < input_min)
            input_min = x;
        if (x > input_max)
            input_max = x;

        nsamples++;
        n = nsamples;
        if (method) {
            sum += x;
            sumsq += x * x;
            mean = sum / n;
            variance = (sumsq - sum * sum / n) / (n - 1);
        } else {
            double delta = x - mean;

            mean += delta / n;
            m2 += delta * (x - mean);
            variance = m2 / (n - 1);
        }
    }

    if (index < 0 || index >= (int)nbins)
        binvalue = -1;
    else
        binvalue = bins[index];
}
