component hclogic "Personality: sized arrays and conditional pins";
pin in bit in-##[16 : personality & 0xff];
pin out bit and if personality & 0x100;
pin out bit or if personality & 0x200;
pin out bit xor if personality & 0x400;
function _ nofp;
option default_personality 0x103;
license "GPL";
;;
FUNCTION(_) {
    int i, a = 1, o = 0, x = 0;
    for (i = 0; i < (personality & 0xff); i++) {
        if (in(i)) { o = 1; x = !x; }
        else { a = 0; }
    }
    if (personality & 0x100) and = a;
    if (personality & 0x200) or = o;
    if (personality & 0x400) xor = x;
}
