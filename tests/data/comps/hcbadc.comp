component hcbadc;
pin out float out;
function _;
license "GPL";
;;
FUNCTION(_) {
    out = 1.0;
    out = undefined_thing + 2;
}
