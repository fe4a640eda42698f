component offset "Add an offset to a command and take it off the matching feedback";

pin in float offset "The offset to apply";
pin in float in "The command input";
pin out float out "in + offset";
pin in float fb_in "The feedback input";
pin out float fb_out "fb-in - offset";

function update_output fp "Compute out from in and offset";
function update_feedback fp "Compute fb-out from fb-in and offset";

description """
Put \\fBupdate-output\\fR before the consumer of \\fBout\\fR and
\\fBupdate-feedback\\fR after the producer of \\fBfb-in\\fR; the two can be in
different threads.
""";
author "the halsdk authors";
license "GPL";
;;
FUNCTION(update_output) { out = in + offset; }

FUNCTION(update_feedback) { fb_out = fb_in - offset; }
