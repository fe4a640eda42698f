component threadtest "Count the runs of a thread, to test threads";

description """
A tool for testing threads: \\fBincrement\\fR adds one to \\fBcount\\fR
each time it runs and \\fBreset\\fR sets it back to zero. Put
\\fBincrement\\fR in one thread and \\fBreset\\fR in another, and
\\fBcount\\fR shows how many times the first ran between two runs of the
second; or watch \\fBcount\\fR with halmeter or halscope to see that a
thread runs at all.
""";

pin out u32 count "Number of runs of increment since the last reset (wraps to 0 after 4294967295)";

function increment nofp "Add one to count";
function reset nofp "Set count to zero";

see_also "timedelta(9)";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(increment) { count++; }

FUNCTION(reset) { count = 0; }
