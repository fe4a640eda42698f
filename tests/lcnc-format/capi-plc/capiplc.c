/********************************************************************
 * capiplc.c - a small PLC-style block for HAL: ladder-like rungs of
 * AND/OR logic over arrays of bit pins, with on-delay and off-delay
 * timers and up counters.
 ********************************************************************/

#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_string.h"
#include "hal.h"

MODULE_AUTHOR("Example Author");
MODULE_DESCRIPTION("PLC-style rung/timer/counter block for HAL");
MODULE_LICENSE("GPL");

#define MAX_CHAN 8
#define MAX_IN 16

static int count = 1;
RTAPI_MP_INT(count, "number of PLC blocks");
static int inputs[MAX_CHAN] = { 4, 4, 4, 4, 4, 4, 4, 4 };
RTAPI_MP_ARRAY_INT(inputs, MAX_CHAN, "inputs per block");
static char *names[MAX_CHAN] = { 0, };
RTAPI_MP_ARRAY_STRING(names, MAX_CHAN, "names of the blocks");
static char *mode = "and";
RTAPI_MP_STRING(mode, "rung logic: and or or");
static long scan_limit = 1000000;
RTAPI_MP_LONG(scan_limit, "counts above this are clamped");

typedef struct {
    hal_bit_t *in[MAX_IN];
    hal_bit_t *rung;          /* the logic result */
    hal_bit_t *ton_q;         /* on-delay output */
    hal_bit_t *tof_q;         /* off-delay output */
    hal_bit_t *reset;
    hal_s32_t *cv;            /* counter value */
    hal_float_t *elapsed;
    hal_float_t ton_pt;       /* params */
    hal_float_t tof_pt;
    hal_s32_t pv;
    hal_bit_t cnt_q;
    int nin;
    int use_or;
    double ton_acc;
    double tof_acc;
    int last_rung;
    char name[HAL_NAME_LEN + 1];
} plc_t;

static int comp_id;
static plc_t *plc_array;
static int nblocks;
static long long start_time;

static void plc_update(void *arg, long period)
{
    plc_t *p = arg;
    double dt = period * 1e-9;
    int i, r;

    r = p->use_or ? 0 : 1;
    for (i = 0; i < p->nin; i++) {
        if (p->use_or)
            r = r || *(p->in[i]);
        else
            r = r && *(p->in[i]);
    }
    *(p->rung) = r;

    if (r) {
        p->ton_acc += dt;
        if (p->ton_acc >= p->ton_pt) {
            p->ton_acc = p->ton_pt;
            *(p->ton_q) = 1;
        }
        p->tof_acc = 0;
        *(p->tof_q) = 1;
    } else {
        p->ton_acc = 0;
        *(p->ton_q) = 0;
        if (*(p->tof_q)) {
            p->tof_acc += dt;
            if (p->tof_acc >= p->tof_pt) {
                *(p->tof_q) = 0;
                p->tof_acc = 0;
            }
        }
    }
    *(p->elapsed) = p->ton_acc;

    if (*(p->reset)) {
        *(p->cv) = 0;
    } else if (r && !p->last_rung && *(p->cv) < scan_limit) {
        (*(p->cv))++;
    }
    p->cnt_q = *(p->cv) >= p->pv;
    p->last_rung = r;
}

static int export_plc(int n, plc_t *p)
{
    int retval, i;
    char buf[HAL_NAME_LEN + 1];

    p->nin = inputs[n];
    if (p->nin < 1 || p->nin > MAX_IN) {
        rtapi_print_msg(RTAPI_MSG_ERR,
            "CAPIPLC: ERROR: inputs[%d]=%d is out of range 1..%d\n",
            n, p->nin, MAX_IN);
        return -EINVAL;
    }
    p->use_or = strcmp(mode, "or") == 0;
    if (names[n] && names[n][0])
        rtapi_strxcpy(p->name, names[n]);
    else
        rtapi_snprintf(p->name, sizeof(p->name), "capiplc.%d", n);

    for (i = 0; i < p->nin; i++) {
        retval = hal_pin_bit_newf(HAL_IN, &(p->in[i]), comp_id,
                                  "%s.in-%02d", p->name, i);
        if (retval != 0)
            return retval;
    }
    retval = hal_pin_bit_newf(HAL_OUT, &(p->rung), comp_id, "%s.rung",
                              p->name);
    if (retval != 0) return retval;
    retval = hal_pin_bit_newf(HAL_OUT, &(p->ton_q), comp_id, "%s.ton-q",
                              p->name);
    if (retval != 0) return retval;
    retval = hal_pin_bit_newf(HAL_OUT, &(p->tof_q), comp_id, "%s.tof-q",
                              p->name);
    if (retval != 0) return retval;
    retval = hal_pin_bit_newf(HAL_IN, &(p->reset), comp_id, "%s.reset",
                              p->name);
    if (retval != 0) return retval;
    retval = hal_pin_s32_newf(HAL_OUT, &(p->cv), comp_id, "%s.cv",
                              p->name);
    if (retval != 0) return retval;
    retval = hal_pin_float_newf(HAL_OUT, &(p->elapsed), comp_id,
                                "%s.elapsed", p->name);
    if (retval != 0) return retval;
    retval = hal_param_float_newf(HAL_RW, &(p->ton_pt), comp_id,
                                  "%s.ton-pt", p->name);
    if (retval != 0) return retval;
    retval = hal_param_float_newf(HAL_RW, &(p->tof_pt), comp_id,
                                  "%s.tof-pt", p->name);
    if (retval != 0) return retval;
    retval = hal_param_s32_newf(HAL_RW, &(p->pv), comp_id, "%s.pv",
                                p->name);
    if (retval != 0) return retval;
    retval = hal_param_bit_newf(HAL_RO, &(p->cnt_q), comp_id, "%s.cnt-q",
                                p->name);
    if (retval != 0) return retval;

    p->ton_pt = 0.01;
    p->tof_pt = 0.01;
    p->pv = 3;
    *(p->cv) = 0;

    rtapi_snprintf(buf, sizeof(buf), "%s.update", p->name);
    retval = hal_export_funct(buf, plc_update, p, 1, 0, comp_id);
    if (retval != 0) {
        rtapi_print_msg(RTAPI_MSG_ERR,
            "CAPIPLC: ERROR: function export for %s failed\n", p->name);
        return retval;
    }
    return 0;
}

int rtapi_app_main(void)
{
    int n, retval;

    if (count < 1 || count > MAX_CHAN) {
        rtapi_print_msg(RTAPI_MSG_ERR,
            "CAPIPLC: ERROR: invalid count: %d\n", count);
        return -EINVAL;
    }
    nblocks = count;
    comp_id = hal_init("capiplc");
    if (comp_id < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "CAPIPLC: ERROR: hal_init() failed\n");
        return -EINVAL;
    }
    plc_array = hal_malloc(nblocks * sizeof(plc_t));
    if (plc_array == 0) {
        rtapi_print_msg(RTAPI_MSG_ERR,
            "CAPIPLC: ERROR: hal_malloc() failed\n");
        hal_exit(comp_id);
        return -ENOMEM;
    }
    for (n = 0; n < nblocks; n++) {
        retval = export_plc(n, &(plc_array[n]));
        if (retval != 0) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                "CAPIPLC: ERROR: block %d export failed\n", n);
            hal_exit(comp_id);
            return -1;
        }
    }
    start_time = rtapi_get_time();
    if (rtapi_get_clocks() == 0 && start_time == 0)
        rtapi_print_msg(RTAPI_MSG_WARN, "CAPIPLC: no clock\n");
    rtapi_print_msg(RTAPI_MSG_INFO, "CAPIPLC: installed %d blocks\n",
                    nblocks);
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
