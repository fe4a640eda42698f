component time "Run time clock: hours, minutes and seconds while a program runs";

description """
Counts how long \\fBstart\\fR has been TRUE, leaving out the time while
\\fBpause\\fR is TRUE, and shows it as hours, minutes and seconds, for a
cycle-time display on a GUI panel.

The count goes back to zero when \\fBstart\\fR or \\fBpause\\fR becomes TRUE
while both were FALSE. The outputs change only while the clock counts
(\\fBstart\\fR TRUE, \\fBpause\\fR FALSE): between two runs they keep showing
the length of the last run, and the new run starts its display from zero.

Connect \\fBstart\\fR to \\fBhalui.program.is-running\\fR and \\fBpause\\fR to
\\fBhalui.program.is-paused\\fR: the clock then counts the running time of
a program without its pauses. With \\fBpause\\fR left unconnected, a pause
(which makes is-running FALSE) ends the run, and resuming starts from
zero. Example:
.PP
.nf
loadrt time
addf time.0 servo-thread
net prog-running halui.program.is-running => time.0.start
net prog-paused  halui.program.is-paused  => time.0.pause
net cycle-hours   time.0.hours   => pyvcp.time-hours
net cycle-minutes time.0.minutes => pyvcp.time-minutes
net cycle-seconds time.0.seconds => pyvcp.time-seconds
.fi
.PP
The time is the sum of the thread periods in which the clock counted.
""";

pin in bit start "Count while TRUE (unless paused)";
pin in bit pause = 0 "Hold the count while TRUE";
pin out u32 seconds "Seconds of the counted time, 0 to 59";
pin out u32 minutes "Minutes of the counted time, 0 to 59";
pin out u32 hours "Whole hours of the counted time";

function _ "Count one thread period and update the outputs";

variable rtapi_u64 elapsed_ns;
variable int was_active;

see_also "timedelta(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(_) {
    int active = start || pause;

    if (active && !was_active)
        elapsed_ns = 0;
    was_active = active;
    if (start && !pause) {
        rtapi_u64 secs;

        elapsed_ns += period;
        secs = elapsed_ns / 1000000000u;
        seconds = secs % 60;
        minutes = (secs / 60) % 60;
        hours = secs / 3600;
    }
}
