/*
 * capimp.c - module parameters of every kind, reflected in pins: one
 * channel per name in names= (or count= channels named capimp.N).
 */

#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_string.h"
#include "hal.h"

MODULE_AUTHOR("Example Author");
MODULE_DESCRIPTION("module parameters shown as pins");
MODULE_LICENSE("GPL");

#define MAX_CHAN 6

static int count = 0;
RTAPI_MP_INT(count, "number of channels when names= is not given");
static char *names[MAX_CHAN];
RTAPI_MP_ARRAY_STRING(names, MAX_CHAN, "names of the channels");
static int cfg[MAX_CHAN] = { 1, 2, 3, 4, 5, 6 };
RTAPI_MP_ARRAY_INT(cfg, MAX_CHAN, "a number per channel");
static long limit = -5;
RTAPI_MP_LONG(limit, "a long number");
static long scale[MAX_CHAN];
RTAPI_MP_ARRAY_LONG(scale, MAX_CHAN, "a long per channel");
static char *label = "none";
RTAPI_MP_STRING(label, "a word");

typedef struct {
    hal_s32_t *cfg;
    hal_s32_t *limit;
    hal_s32_t *scale;
    hal_u32_t *label_len;
    hal_bit_t *named;
    hal_u32_t index;
} chan_t;

static int comp_id;
static chan_t *chans;

static int make_chan(int n, const char *name)
{
    chan_t *c = &chans[n];
    int r;

    r = hal_pin_s32_newf(HAL_OUT, &c->cfg, comp_id, "%s.cfg", name);
    if (r == 0)
        r = hal_pin_s32_newf(HAL_OUT, &c->limit, comp_id, "%s.limit", name);
    if (r == 0)
        r = hal_pin_s32_newf(HAL_OUT, &c->scale, comp_id, "%s.scale", name);
    if (r == 0)
        r = hal_pin_u32_newf(HAL_OUT, &c->label_len, comp_id,
                             "%s.label-len", name);
    if (r == 0)
        r = hal_pin_bit_newf(HAL_OUT, &c->named, comp_id, "%s.named", name);
    if (r == 0)
        r = hal_param_u32_newf(HAL_RO, &c->index, comp_id, "%s.index",
                               name);
    if (r)
        return r;
    *(c->cfg) = cfg[n];
    *(c->limit) = (hal_s32_t)limit;
    *(c->scale) = (hal_s32_t)scale[n];
    *(c->label_len) = strlen(label);
    *(c->named) = names[n] != NULL;
    c->index = n;
    return 0;
}

int rtapi_app_main(void)
{
    int n, nchan = 0, r;
    char buf[HAL_NAME_LEN + 1];

    if (names[0]) {
        for (nchan = 0; nchan < MAX_CHAN && names[nchan]; nchan++)
            ;
        if (count) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "CAPIMP: ERROR: count= and names= together\n");
            return -EINVAL;
        }
    } else {
        nchan = count ? count : 1;
    }
    if (nchan > MAX_CHAN) {
        rtapi_print_msg(RTAPI_MSG_ERR, "CAPIMP: ERROR: count=%d is more "
                        "than %d\n", nchan, MAX_CHAN);
        return -EINVAL;
    }
    comp_id = hal_init("capimp");
    if (comp_id < 0)
        return comp_id;
    chans = hal_malloc(nchan * sizeof(chan_t));
    if (!chans) {
        hal_exit(comp_id);
        return -ENOMEM;
    }
    for (n = 0; n < nchan; n++) {
        if (names[n])
            rtapi_strxcpy(buf, names[n]);
        else
            rtapi_snprintf(buf, sizeof(buf), "capimp.%d", n);
        r = make_chan(n, buf);
        if (r) {
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
