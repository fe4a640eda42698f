/* hcprog.c: a hand-written userspace HAL program (halcompile -u).
 * Usage: hcprog [gain]. Pins hcprog.in, hcprog.out = gain * in, and
 * hcprog.loops; on SIGTERM it leaves its loop, removes its component and
 * returns 0; with "fail" as its argument it returns 3 at once. */
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hal.h"
#include "rtapi.h"

typedef struct {
    hal_float_t *in;
    hal_float_t *out;
    hal_u32_t *loops;
} data_t;

static volatile sig_atomic_t done;

static void quit(int sig)
{
    (void)sig;
    done = 1;
}

int main(int argc, char **argv)
{
    double gain = 1.0;
    data_t *d;
    int id;

    if (argc > 1 && strcmp(argv[1], "fail") == 0)
        return 3;
    if (argc > 1)
        gain = atof(argv[1]);
    id = hal_init("hcprog");
    if (id < 0)
        return 1;
    d = hal_malloc(sizeof(*d));
    if (!d || hal_pin_float_new("hcprog.in", HAL_IN, &d->in, id) ||
            hal_pin_float_new("hcprog.out", HAL_OUT, &d->out, id) ||
            hal_pin_u32_new("hcprog.loops", HAL_OUT, &d->loops, id)) {
        hal_exit(id);
        return 1;
    }
    signal(SIGTERM, quit);
    signal(SIGINT, quit);
    hal_ready(id);
    while (!done) {
        *d->out = gain * *d->in;
        (*d->loops)++;
        usleep(1000);
    }
    hal_exit(id);
    return 0;
}
