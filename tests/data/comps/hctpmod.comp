component hctpmod "option tpmod: a singleton module (a trajectory-planner stand-in)";
pin in float v;
pin out float vmax;
function _;
option tpmod yes;
license "GPL";
;;
if (v > vmax) vmax = v;
