component hcuser2 "A singleton userspace component reading argc/argv";
pin out s32 nargs "argc, once count= and names= are taken out";
pin out s32 arglen "total length of the arguments after the name";
pin in bit stop "ends the main loop";
option userspace yes;
option singleton yes;
license "GPL";
;;
#include <string.h>
#include <unistd.h>

void user_mainloop(void)
{
    int i, len = 0;
    for (i = 1; i < argc; i++)
        len += (int)strlen(argv[i]);
    for (;;) {
        FOR_ALL_INSTS() {
            nargs = argc;
            arglen = len;
            if (stop)
                return;
        }
        usleep(1000);
    }
}
