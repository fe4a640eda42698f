component hccyddt "Derivative, with the code section in Cython";
pin in float in_ "the input";
pin out float out "its derivative";
variable double old;
function _;
option cython yes;
license "GPL";
;;
out = (in_ - old) / fperiod
old = in_
