component hcnoconv "option fp no: the functions default to nofp";
pin in u32 a;
pin out u32 shifted;
function _;
option fp no;
license "GPL";
;;
shifted = (a << 4) | 0xF;
