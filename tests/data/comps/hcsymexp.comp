component hcsymexp "Offers a function, a variable and a shared block to other modules";
pin out s32 counter "cycles run";
function _ nofp;
option singleton yes;
option extra_setup yes;
license "GPL";
;;
int hcsym_scale = 3;
EXPORT_SYMBOL(hcsym_scale);

int hcsym_twice(int x)
{
    return 2 * x;
}
EXPORT_SYMBOL(hcsym_twice);

FUNCTION(_) {
    counter++;
}

EXTRA_SETUP() {
    long long h = HALSDK_API->shmem_new("hcsym.block", comp_id, 256);
    unsigned char *p;
    if (h < 0)
        return (int)h;
    p = HALSDK_API->shmem_ptr(h);
    for (int i = 0; i < 256; i++)
        p[i] = (unsigned char)i;
    return 0;
}
