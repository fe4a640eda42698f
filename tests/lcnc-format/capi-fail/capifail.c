/*
 * capifail.c - a module whose rtapi_app_main() can fail half-way.  Its
 * rtapi_app_exit() relies on the state that a successful
 * rtapi_app_main() made, as exit code usually does: it must not be
 * called after a failed load.
 */

#include "rtapi.h"
#include "rtapi_app.h"
#include "hal.h"

MODULE_LICENSE("GPL");

typedef struct {
    hal_bit_t *out;
    hal_u32_t *value;
    int *history;
} chan_t;

static int comp_id = -1;
static chan_t *chans;
static int fail = 1;
RTAPI_MP_INT(fail, "1: rtapi_app_main fails after making pins");
static int value = 7;
RTAPI_MP_INT(value, "the value of the value pin");

int rtapi_app_main(void)
{
    int r;

    comp_id = hal_init("capifail");
    if (comp_id < 0)
        return comp_id;
    if (fail) {
        /* a pin exists already when the load fails */
        hal_bit_t **early = hal_malloc(sizeof(hal_bit_t *));
        r = hal_pin_bit_new("capifail.early", HAL_OUT, early, comp_id);
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "CAPIFAIL: ERROR: told to fail (%d)\n", r);
        hal_exit(comp_id);
        return -EINVAL;
    }
    chans = hal_malloc(sizeof(chan_t));
    if (!chans) {
        hal_exit(comp_id);
        return -ENOMEM;
    }
    chans->history = NULL;
    r = hal_pin_bit_new("capifail.out", HAL_OUT, &chans->out, comp_id);
    if (r == 0)
        r = hal_pin_u32_new("capifail.value", HAL_OUT, &chans->value,
                            comp_id);
    if (r) {
        hal_exit(comp_id);
        return r;
    }
    *(chans->out) = 1;
    *(chans->value) = value;
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    /* chans exists only when rtapi_app_main succeeded */
    chans->history = NULL;
    *(chans->out) = 0;
    hal_exit(comp_id);
}
