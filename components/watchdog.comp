component watchdog "Check that several heartbeat inputs keep changing";

description """
Watches up to 32 bit inputs that should keep toggling, such as the
heartbeat (charge-pump, watchdog) output of a program or of another
machine. \\fBok-out\\fR is TRUE while \\fBenable-in\\fR is TRUE and every
input has changed at least once within its own timeout.

Once an input has been quiet for longer than its timeout, \\fBok-out\\fR
goes FALSE and stays FALSE, even when the input starts toggling again,
until \\fBenable-in\\fR goes FALSE and back to TRUE. The rising edge of
\\fBenable-in\\fR sets \\fBok-out\\fR and starts every input's timeout
afresh.

Load it with \\fBnum_inputs=\\fIN\\fR (1 to 32; there is no default). There
is one watchdog per load: the pins, params and functions are named
\\fBwatchdog.\\fR\\fIitem\\fR.

Add \\fBwatchdog.process\\fR (no floating point) to a thread fast enough to
see every change of the inputs, usually the base thread; add
\\fBwatchdog.set-timeouts\\fR (floating point) to a slower one, usually the
servo thread. A timeout is counted in periods of the thread that runs
\\fBwatchdog.process\\fR.
""";

pin in bit input_n "Heartbeat input \\fIn\\fR (0 to num_inputs\\-1): it must change within timeout-\\fIn\\fR";
pin in bit enable_in = false "Turn the watchdog on: ok-out can only be TRUE while this is TRUE, and a rising edge restarts the monitoring after a timeout";
pin out bit ok_out = false "TRUE while enabled and no input has timed out; connect it, for example, to a charge pump or a stepgen enable";

param rw float timeout_n "Longest time in seconds that input \\fIn\\fR may stay unchanged; a negative value acts as 0 (an input then times out in each cycle in which it does not change), and a very long one makes the watchdog useless";

function process nofp "Look for changes of the inputs and clear ok-out when one times out";
function set_timeouts "Take the timeouts and enable-in into account";

modparam int num_inputs = 0 "Number of inputs, 1 to 32; required";

option singleton yes;
option rtapi_app no;

see_also "charge_pump(9)";
license "GPL";
author "the halsdk authors";
;;
#define MAX_INPUTS 32

/* One watchdog a load, with a variable number of inputs: the
   declarations above document the items, this is what holds them. */
struct wd_input {
    hal_bit_t *in;
    hal_float_t timeout;
    rtapi_s64 limit_ns;         /* timeout, in ns, as last taken */
    rtapi_s64 left_ns;          /* time left until it times out */
    int last;                   /* input value seen last */
};

static struct wd_state {
    hal_bit_t *enable;          /* enable-in */
    hal_bit_t *ok;              /* ok-out */
    int was_enabled;
    struct wd_input inputs[MAX_INPUTS];
} *wd;

FUNCTION(process) {
    int n;

    for (n = 0; n < num_inputs; n++) {
        struct wd_input *p = &wd->inputs[n];
        int in = *p->in;

        if (in != p->last) {
            p->last = in;
            p->left_ns = p->limit_ns;
        } else {
            p->left_ns -= period;
            if (p->left_ns < 0)
                *wd->ok = 0;
        }
    }
}

FUNCTION(set_timeouts) {
    int n;

    for (n = 0; n < num_inputs; n++) {
        struct wd_input *p = &wd->inputs[n];

        p->limit_ns = p->timeout > 0 ? (rtapi_s64)(p->timeout * 1e9) : 0;
    }
    if (!*wd->enable) {
        *wd->ok = 0;
    } else if (!wd->was_enabled) {
        /* switched on: start all timeouts afresh */
        for (n = 0; n < num_inputs; n++)
            wd->inputs[n].left_ns = wd->inputs[n].limit_ns;
        *wd->ok = 1;
    }
    wd->was_enabled = *wd->enable;
}

int rtapi_app_main(void)
{
    int n, r;

    if (num_inputs < 1) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "WATCHDOG: ERROR: must specify at least one input\n");
        return -1;
    }
    if (num_inputs > MAX_INPUTS) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "WATCHDOG: ERROR: too many inputs requested "
                        "(%d > %d)\n", num_inputs, MAX_INPUTS);
        return -1;
    }
    comp_id = hal_init("watchdog");
    if (comp_id < 0)
        return comp_id;
    wd = hal_malloc(sizeof(*wd));
    r = wd ? 0 : -ENOMEM;
    if (!r)
        memset(wd, 0, sizeof(*wd));
    for (n = 0; !r && n < num_inputs; n++) {
        r = hal_pin_bit_newf(HAL_IN, &wd->inputs[n].in, comp_id,
                             "watchdog.input-%d", n);
        if (!r)
            r = hal_param_float_newf(HAL_RW, &wd->inputs[n].timeout,
                                     comp_id, "watchdog.timeout-%d", n);
    }
    if (!r)
        r = hal_pin_bit_newf(HAL_IN, &wd->enable, comp_id,
                             "watchdog.enable-in");
    if (!r)
        r = hal_pin_bit_newf(HAL_OUT, &wd->ok, comp_id,
                             "watchdog.ok-out");
    if (!r)
        r = hal_export_funct("watchdog.process",
                             (void (*)(void *, long))process, NULL, 0, 0,
                             comp_id);
    if (!r)
        r = hal_export_funct("watchdog.set-timeouts",
                             (void (*)(void *, long))set_timeouts, NULL, 1,
                             0,
                             comp_id);
    if (r) {
        hal_exit(comp_id);
        return r;
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
