component hcuser3 "A userspace component with count, FOR_ALL_INSTS, an array and a hex default";
pin in s32 in-#[3];
pin out s32 sum;
pin out s32 passes;
pin in bit quit;
param rw s32 bias = 0x10;
option userspace yes;
license "GPL";
;;
#include <unistd.h>

void user_mainloop(void)
{
    while (1) {
        usleep(2000);
        FOR_ALL_INSTS() {
            if (quit)
                return;
            {
                int i, s = bias;
                for (i = 0; i < 3; i++)
                    s += in(i);
                sum = s;
            }
            passes++;
        }
    }
}
