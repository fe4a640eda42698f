component hcuser "A userspace component: scales its input in user_mainloop";
description """Each instance copies in * scale to out and counts its passes;
scale comes from the command line (scale=X), read in userinit.""";
pin in float in_ "the input";
pin out float out "in times the scale";
pin out s32 passes "passes of the main loop over this instance";
pin in bit quit "when true, user_mainloop returns and the program ends";
param rw float offset = 0.5 "added to out";
variable int seen;
option userspace yes;
option userinit yes;
license "GPL";
author "halsdk tests";
;;
#include <unistd.h>
#include <stdlib.h>
#include <string.h>

static double scale = 1.0;
static int nargs;

void userinit(int argc, char **argv)
{
    int i;
    nargs = argc;
    for (i = 1; i < argc; i++)
        if (strncmp(argv[i], "scale=", 6) == 0)
            scale = strtod(argv[i] + 6, NULL);
}

void user_mainloop(void)
{
    while (1) {
        int stop = 0;
        usleep(1000);
        FOR_ALL_INSTS() {
            out = in_ * scale + offset + nargs * 0;
            passes++;
            seen = 1;
            if (quit)
                stop = 1;
        }
        if (stop)
            return;
    }
}
