component hcddt "Compute the derivative of the input function";
pin in float in;
pin out float out;
variable double old;
function _;
license "GPL"; // GPL v2 or later
author "halsdk tests";
;;
double tmp = in;
out = (tmp - old) / fperiod;
old = tmp;
