component hcimplicit2 "An implicit body with a named function and fperiod";
pin out float t;
pin out s32 ns;
function tick;
license "GPL";
;;
t += fperiod;
ns = period;
