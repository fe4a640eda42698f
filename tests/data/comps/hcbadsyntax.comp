component hcbadsyntax;
pin out float out;
pin out flaot other;
function _;
license "GPL";
;;
out = 1;
