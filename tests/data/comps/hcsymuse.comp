component hcsymuse "Uses what hcsymexp offers: out = scale * twice(in)";
pin in s32 in;
pin out s32 out;
function _ nofp;
option rtapi_app no;
license "GPL";
;;
static int (*twice)(int);
static int *scale;

FUNCTION(_) {
    out = *scale * twice(in);
}

int rtapi_app_main(void)
{
    int r;
    twice = halsdk_symbol_find("hcsym_twice");
    scale = halsdk_symbol_find("hcsym_scale");
    if (!twice || !scale) {
        rtapi_print_msg(RTAPI_MSG_ERR, "hcsymuse: load hcsymexp first\n");
        return -ENOENT;
    }
    comp_id = hal_init("hcsymuse");
    if (comp_id < 0)
        return comp_id;
    r = export("hcsymuse", 0);
    if (r) {
        hal_exit(comp_id);
        return r;
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
