component hcuserlink "A userspace component with extra_compile_args and extra_link_args (libm)";
pin in float x = 2;
pin out float y "x raised to the power GAIN";
pin in bit quit;
option userspace yes;
option extra_compile_args "-DGAIN=3";
option extra_link_args "-lm";
license "GPL";
;;
#include <unistd.h>
#include <math.h>

void user_mainloop(void)
{
    while (1) {
        usleep(2000);
        FOR_ALL_INSTS() {
            if (quit)
                return;
            y = pow(x, GAIN);
        }
    }
}
