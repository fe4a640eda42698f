component hcrstring r"Raw strings: \fIdoc\fR with backslashes kept";
pin in float in r"the \fBinput\fR";
pin out float out r"""the \fBoutput\fR,
raw over two lines""";
function _ r"copies \fIin\fR";
license "GPL";
;;
out = in * 3;
