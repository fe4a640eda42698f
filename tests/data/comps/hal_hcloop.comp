component hal_hcloop "hal_ prefix: items are named hcloop.N";
pin out float example = 4.25;
function _;
license "GPL";
;;
example = example * 2;
