component hchash "Runs of # in names, in the middle and at the end";
pin out s32 out-###[3];
pin out s32 stage.##.value[2];
param rw s32 k-#[2] = 5;
function _ nofp;
license "GPL";
;;
FUNCTION(_) {
    int i;
    for (i = 0; i < 3; i++)
        out(i) = 10 * i + k(0);
    for (i = 0; i < 2; i++)
        stage_value(i) = k(1) * (i + 1);
}
