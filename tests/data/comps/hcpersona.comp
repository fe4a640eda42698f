component hcpersona "Conditional pins and a personality-sized array";
pin in float in-#[8 : personality & 7] "the summed inputs";
pin out float sum;
pin out s32 pers;
pin out float scaled if personality & 0x10 "sum times gain, with bit 4 set";
param rw float gain if personality & 0x10;
pin out bit neg if personality & 0x20;
function _;
license "GPL";
;;
FUNCTION(_) {
    int i;
    double s = 0;
    for (i = 0; i < (personality & 7); i++)
        s += in(i);
    sum = s;
    pers = personality;
    if (personality & 0x10)
        scaled = s * gain;
    if (personality & 0x20)
        neg = s < 0;
}
