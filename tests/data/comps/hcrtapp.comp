component hcrtapp "option rtapi_app no: the code section makes the instances";
pin out s32 out;
param rw s32 k = 2;
function _ nofp;
option rtapi_app no;
license "GPL";
;;
static int n_inst = 2;
RTAPI_MP_INT(n_inst, "number of instances");

FUNCTION(_) {
    out = k * (period / 1000);
}

int rtapi_app_main(void)
{
    comp_id = hal_init("hcrtapp");
    if (comp_id < 0)
        return comp_id;
    for (int i = 0; i < n_inst; i++) {
        char name[HAL_NAME_LEN + 1];
        int r;
        rtapi_snprintf(name, sizeof(name), "rt-%c", 'a' + i);
        r = export(name, i);
        if (r != 0) {
            hal_exit(comp_id);
            return r;
        }
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
