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

param rw float timeout_n "Longest time in seconds that input \\fIn\\fR may stay unchanged; a value of 0 or less makes an input time out in each cycle in which it does not change; one that is not a number, or too large for a count of nanoseconds (about 9.2e9 s either way), never times out, as in the reference";

function process nofp "Look for changes of the inputs and clear ok-out when one times out";
function set_timeouts "Take the timeouts and enable-in into account";

modparam int num_inputs = 0 "Number of inputs, 1 to 32; required";

option singleton yes;
option rtapi_app no;

notes """While \\fBenable-in\\fR is FALSE (and after a timeout, until
its next rising edge), the inputs are not watched and their values are
not taken: at the rising edge, an input that differs from the value seen
last counts as a change.

LinuxCNC 2.9's watchdog leaves \\fBok-out\\fR TRUE when \\fBenable-in\\fR
goes FALSE (until the next timeout after a new rising edge), against its
own manual page; this one makes \\fBok-out\\fR FALSE while
\\fBenable-in\\fR is FALSE, as documented.""";
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
    int watching;               /* from a rising edge of enable-in to a timeout */
    struct wd_input inputs[MAX_INPUTS];
} *wd;

FUNCTION(process) {
    int n;

    /* as the reference, nothing is watched (nor are the inputs' values
       taken) while enable-in is FALSE or after a timeout, until the next
       rising edge of enable-in: an input that differs then from the value
       seen last counts as a change */
    if (!*wd->enable || !wd->watching)
        return;
    for (n = 0; n < num_inputs; n++) {
        struct wd_input *p = &wd->inputs[n];
        int in = *p->in;

        if (in != p->last) {
            p->last = in;
            p->left_ns = p->limit_ns;
        } else {
            /* wraps as the reference's count does: the count of a timeout
               that is not a number or is out of range starts at the most
               negative value and wraps to a positive one, so that such an
               input never times out */
            p->left_ns = (rtapi_s64)((rtapi_u64)p->left_ns
                                     - (rtapi_u64)period);
            if (p->left_ns < 0) {
                *wd->ok = 0;
                wd->watching = 0;
            }
        }
    }
}

/* a timeout in ns as the reference converts it: a value out of the
   s64 range, or not a number, gives the most negative s64 */
static rtapi_s64 timeout_ns(double t)
{
    double ns = t * 1e9;

    if (ns > -9223372036854775808.0 && ns < 9223372036854775808.0)
        return (rtapi_s64)ns;
    return (rtapi_s64)((rtapi_u64)1 << 63);
}

FUNCTION(set_timeouts) {
    int n;

    for (n = 0; n < num_inputs; n++) {
        struct wd_input *p = &wd->inputs[n];

        p->limit_ns = timeout_ns(p->timeout);
    }
    if (!*wd->enable) {
        /* the reference leaves ok-out TRUE here (see the notes) */
        *wd->ok = 0;
    } else if (!wd->was_enabled) {
        /* switched on: start all timeouts afresh */
        for (n = 0; n < num_inputs; n++)
            wd->inputs[n].left_ns = wd->inputs[n].limit_ns;
        *wd->ok = 1;
        wd->watching = 1;
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
