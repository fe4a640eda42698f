component timedelta "Measure how regularly a thread runs";

description """
Add \\fBtimedelta.\\fIN\\fR to a thread to see how evenly the thread is
scheduled: each time it runs, it reads the clock (rtapi_get_time) and
compares the time since its previous run with the thread period.

The first run after loading (or after a reset) only reads the clock. The
first measured interval sets \\fBmin\\fR and \\fBmax\\fR and adds to
\\fBerr\\fR, but leaves \\fBcurrent-error\\fR and \\fBcurrent-jitter\\fR
alone; from the second one on, all outputs follow.

While \\fBreset\\fR is TRUE, each run zeroes \\fBout\\fR, \\fBmax\\fR and
\\fBjitter\\fR and forgets the previous clock reading, so measuring starts
afresh when \\fBreset\\fR goes FALSE. \\fBmin\\fR, \\fBerr\\fR,
\\fBavg-err\\fR and the current-* outputs are not reset.
""";

pin out s32 jitter = 0 "Largest current-jitter seen since the last reset, in ns";
pin out s32 current_jitter = 0 "Absolute value of current-error, in ns";
pin out s32 current_error = 0 "Interval of this run minus the thread period, in ns: negative when the thread ran early, positive when late";
pin out s32 min = 0 "Shortest interval between two runs, in ns";
pin out s32 max = 0 "Longest interval between two runs since the last reset, in ns";
pin in bit reset "While TRUE, zero out, max and jitter and restart the measurement when it goes FALSE";
pin out s32 out "Time since the previous run, in ns; ideally the thread period";
pin out s32 err = 0 "Sum of all interval errors (interval minus period), in ns";
pin out float avg_err = 0 "err divided by the number of runs counted, in ns";

function _ nofp "Read the clock and update the statistics";

variable rtapi_s64 last_ns;
variable int have_last;
variable int measured;
variable rtapi_s64 runs = 1;

see_also "threadtest(9), latencybins(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    rtapi_s64 now = rtapi_get_time();

    if (have_last) {
        rtapi_s32 del = (rtapi_s32)(now - last_ns);

        out = del;
        err = err + del - period;
        if (!measured) {
            /* the first interval has nothing to compare with yet */
            measured = 1;
            min = del;
            max = del;
            jitter = 0;
        } else {
            current_error = del - period;
            current_jitter = current_error < 0 ? -current_error
                                               : current_error;
            if (del < min)
                min = del;
            if (del > max)
                max = del;
            if (current_jitter > jitter)
                jitter = current_jitter;
        }
        runs++;
        avg_err = err / (double)runs;
    }
    if (reset) {
        measured = 0;
        have_last = 0;
        out = 0;
        jitter = 0;
        max = 0;
    } else {
        last_ns = now;
        have_last = 1;
    }
}
