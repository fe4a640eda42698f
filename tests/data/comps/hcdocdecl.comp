// a comment before the component
component hcdocdecl """All the documentation declarations; the code is a
latch.""";
/* a block
   comment in the declarations */
pin in bit set "raises \\fBout\\fR";
pin in bit reset "lowers \\fBout\\fR";
pin out bit out """the latched value,
on two lines""";
function _ nofp "the only function";
description """A set/reset latch: \\fBset\\fR wins.""";
notes "Written for the halsdk test corpus.";
see_also "hcio(9)";
examples """loadrt hcdocdecl""";
license "GPL v2 or later";
author "halsdk tests";
author "a second author";
;;
FUNCTION(_) {
    if (set) out = 1;
    else if (reset) out = 0;
}
