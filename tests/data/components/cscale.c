/*
 * cscale.c - a scaler written as a LinuxCNC-style C component:
 * out = in * gain + offset, one instance per count.  Uses modparams,
 * hal_malloc, the pin and param constructors and hal_export_functf
 * exactly as reference components do.
 */
#include "rtapi.h"
#include "rtapi_app.h"
#include "hal.h"

MODULE_AUTHOR("halsdk tests");
MODULE_DESCRIPTION("scale a float: out = in * gain + offset");
MODULE_LICENSE("GPL");

static int count = 1;
RTAPI_MP_INT(count, "number of scalers");
static char *prefix = "cscale";
RTAPI_MP_STRING(prefix, "name prefix");
static int limits[4] = {0, 0, 0, 0};
RTAPI_MP_ARRAY_INT(limits, 4, "unused array, for the loader test");

typedef struct {
    hal_float_t *in;
    hal_float_t *out;
    hal_u64_t *calls;
    hal_float_t gain;
    hal_float_t offset;
    hal_s32_t loads;
} scaler_t;

static int comp_id;
static int loads;               /* a static: counts loads of this copy */

static void update(void *arg, long period)
{
    scaler_t *s = arg;
    *s->out = *s->in * s->gain + s->offset;
    (*s->calls)++;
}

int rtapi_app_main(void)
{
    int n, r;
    if (count < 1 || count > 64) {
        rtapi_print_msg(RTAPI_MSG_ERR, "cscale: count=%d is not 1..64\n",
                        count);
        return -EINVAL;
    }
    comp_id = hal_init("cscale");
    if (comp_id < 0)
        return comp_id;
    loads++;
    for (n = 0; n < count; n++) {
        scaler_t *s = hal_malloc(sizeof(scaler_t));
        if (!s) {
            hal_exit(comp_id);
            return -ENOMEM;
        }
        r = hal_pin_float_newf(HAL_IN, &s->in, comp_id, "%s.%d.in",
                               prefix, n);
        if (!r)
            r = hal_pin_float_newf(HAL_OUT, &s->out, comp_id, "%s.%d.out",
                                   prefix, n);
        if (!r)
            r = hal_pin_u64_newf(HAL_OUT, &s->calls, comp_id,
                                 "%s.%d.calls", prefix, n);
        if (!r)
            r = hal_param_float_newf(HAL_RW, &s->gain, comp_id,
                                     "%s.%d.gain", prefix, n);
        if (!r)
            r = hal_param_float_newf(HAL_RW, &s->offset, comp_id,
                                     "%s.%d.offset", prefix, n);
        if (!r)
            r = hal_param_s32_newf(HAL_RO, &s->loads, comp_id,
                                   "%s.%d.loads", prefix, n);
        if (!r)
            r = hal_export_functf(update, s, 1, 0, comp_id, "%s.%d",
                                  prefix, n);
        if (r) {
            hal_exit(comp_id);
            return r;
        }
        s->gain = 1.0;
        s->loads = loads;
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
