component pid """Proportional/integral/derivative controller with feed-forward terms,
limits and a relay auto-tuner""";

description """
pid closes a control loop: it compares \\fBcommand\\fR with \\fBfeedback\\fR and
drives \\fBoutput\\fR so that the two come together.  For a position loop
command and feedback are positions in machine units and output is the
velocity (or torque, or whatever the drive takes) that moves the axis toward
the command.

The loop computes, once per thread period (\\fIT\\fR seconds):
.nf

    error      = command - feedback   (or previous command - feedback,
                                       see error-previous-target)
    e          = error limited to +/-maxerror, then shrunk toward 0
                 by deadband
    errorI    += e * T                (held while the output is at its
                                       limit and e pushes further into it)
    errorI     limited to +/-maxerrorI
    errorD     = command-deriv - feedback-deriv, limited to +/-maxerrorD
    commandD   = command-deriv, limited to +/-maxcmdD
    commandDD  = change of commandD / T, limited to +/-maxcmdDD
    commandDDD = change of commandDD / T, limited to +/-maxcmdDDD
    output     = bias + Pgain*e + Igain*errorI + Dgain*errorD
                 + FF0*command + FF1*commandD + FF2*commandDD
                 + FF3*commandDDD
    output     limited to +/-maxoutput
.fi

A limit of zero means no limit.  While \\fBenable\\fR is false the output is
zero and the integrator is cleared.

When \\fBcommand-deriv\\fR or \\fBfeedback-deriv\\fR is not linked to a signal,
pid estimates it from the change of command or feedback since the previous
period.  Linking feedback-deriv to a velocity estimate (for example the
velocity of encoder(9)) gives a cleaner D term with quantised feedback.

\\fBAuto tuning\\fR: with \\fBtune-mode\\fR true the loop does not run.  Setting
\\fBtune-start\\fR then drives the output to bias +/- tune-effort, switching
each time the error changes sign, so that the axis oscillates around the
command (the relay method of Astrom and Hagglund).  After \\fBtune-cycles\\fR
half cycles the ultimate gain Ku (4 * effort / (pi * amplitude)) and the
ultimate period Tu of the oscillation give the gains: with tune-type 0
(Ziegler-Nichols PID) Pgain = 0.6 Ku, Igain = 2 Pgain / Tu and
Dgain = Pgain Tu / 8; with tune-type 1 (PI plus velocity feed-forward)
Pgain = 0.45 Ku, Igain = 1.2 Pgain / Tu, Dgain = 0 and FF1 = 1.
tune-start is then cleared and the output returns to bias.  Keep the command still while
tuning; clearing enable or tune-mode aborts it.
""";

notes """
A loop of this component counts as saturated once its output is clamped to
+/-maxoutput; the state is kept as it was while maxoutput is zero.

With deadband set, the deadband is subtracted from the error outside the
band (there is no step at its edge).  For encoder feedback a deadband of a
little more than half a count stops the loop hunting between two counts.
""";

modparam dummy num_chan """Number of loops to make (1 to 16, default 3); loops are
named pid.0, pid.1, ...""";
modparam dummy names """Comma-separated names of the loops to make (at most 16),
instead of num_chan""";
modparam int debug = 0 """When not 0, also export the pins errorI, errorD,
commandD, commandDD, commandDDD, ultimate-gain and ultimate-period""";

pin in float Pgain = 1.0 "Proportional gain: output per unit of error.";
pin in float Igain "Integral gain: output per unit of integrated error (unit*second).";
pin in float Dgain "Derivative gain: output per unit of error rate (unit/second).";
pin in float bias "Constant added to the output while the loop is enabled (e.g. to balance a vertical axis).";
pin in float FF0 "Zeroth order feed-forward: output per unit of command.";
pin in float FF1 "First order feed-forward: output per unit of command rate (velocity for a position loop).";
pin in float FF2 "Second order feed-forward: output per unit of command acceleration.";
pin in float FF3 "Third order feed-forward: output per unit of command jerk.";
pin in float deadband "Error smaller than this is taken as zero; a larger error is reduced by it.";
pin in float maxoutput "Limit of the absolute value of output (0: none).";
pin in float maxerror "Limit of the error used by the P, I and D terms (0: none).";
pin in float maxerrorI "Limit of the integrated error errorI (0: none).";
pin in float maxerrorD "Limit of the error derivative errorD (0: none).";
pin in float maxcmdD "Limit of the command derivative commandD (0: none).";
pin in float maxcmdDD "Limit of the command second derivative commandDD (0: none).";
pin in float maxcmdDDD "Limit of the command third derivative commandDDD (0: none).";

pin in float command "Desired value (for a position loop, the commanded position).";
pin in float command_deriv "Derivative of command; when not linked, estimated from the change of command.";
pin in float feedback "Actual value, from a sensor such as an encoder.";
pin in float feedback_deriv "Derivative of feedback; when not linked, estimated from the change of feedback.  A velocity estimate (e.g. encoder(9) velocity) gives a smoother D term.";
pin in bit error_previous_target = 1 "Compute the error from the command of the previous period, as the motion controller expects of a position loop.";
pin in bit enable "Run the loop.  While false, output is 0 and the integrator is cleared.";
pin in bit index_enable "Link to the index-enable signal of an encoder: on its falling edge (the position jumps to the index) the derivative estimates and the previous-target error are not updated, which avoids a one-period output spike.";

pin out float output "Controller output (for a position loop, the velocity command).";
pin out float error "command - feedback (before maxerror and deadband).";
pin out bit saturated "True while the output is clamped to +/-maxoutput.";
pin out float saturated_s "How long the output has been saturated without a break, in seconds.";
pin out s32 saturated_count "How long the output has been saturated without a break, in periods.";

pin out float errorI if debug "Integrated error (debug=1 only).";
pin out float errorD if debug "Error derivative (debug=1 only).";
pin out float commandD if debug "Command derivative (debug=1 only).";
pin out float commandDD if debug "Command second derivative (debug=1 only).";
pin out float commandDDD if debug "Command third derivative (debug=1 only).";

pin in bit tune_mode "True: auto tuning mode; the loop does not run.";
pin io bit tune_start "Set true to start auto tuning; cleared when it ends or is aborted.";
pin io u32 tune_type "0: tune Pgain, Igain and Dgain; 1: tune Pgain and Igain, with FF1 = 1.";
pin io u32 tune_cycles = 50 "Number of half cycles of oscillation to average over.";
pin io float tune_effort = 0.5 "Output swing around bias while tuning (keep below maxoutput).";
pin out float ultimate_gain if debug "Ultimate gain measured by the tuner (debug=1 only).";
pin out float ultimate_period if debug "Ultimate period measured by the tuner, in seconds (debug=1 only).";

variable double prev_cmd;
variable double prev_fb;
variable double ei;
variable double cmd_d;
variable double cmd_dd;
variable double cmd_ddd;
variable double err_d;
variable int prev_ie;
variable int limit_dir;
variable hal_float_t *cmd_d_est;
variable hal_float_t *fb_d_est;

variable int tstate;
variable int tcount;
variable long long tperiod;
variable long long ttotal;
variable double tamp;
variable double tamp_sum;

function do_pid_calcs "Run the loop (or the tuner) once.";

option rtapi_app no;

see_also "encoder(9), at_pid";
author "the halsdk authors";
license "GPL";
;;
#include <rtapi_math.h>

#define MAX_CHAN 16

static int num_chan;
RTAPI_MP_INT(num_chan, "number of pid loops");
static char *names[MAX_CHAN];
RTAPI_MP_ARRAY_STRING(names, MAX_CHAN, "names of the pid loops");

/* tuner states; T_OFF: the normal loop runs */
enum { T_OFF, T_IDLE, T_START, T_POS, T_NEG, T_ABORT };

/* The code below reaches a few input pins' storage itself, which the pin
   names (read-only values in the code section) do not allow. */
#pragma push_macro("command_deriv")
#pragma push_macro("feedback_deriv")
#pragma push_macro("Pgain")
#pragma push_macro("Igain")
#pragma push_macro("Dgain")
#pragma push_macro("FF1")
#pragma push_macro("cmd_d_est")
#pragma push_macro("fb_d_est")
#undef command_deriv
#undef feedback_deriv
#undef Pgain
#undef Igain
#undef Dgain
#undef FF1
#undef cmd_d_est
#undef fb_d_est

/* called right after a loop's pins are made: unlinked, the -deriv pins
   point at their own storage; the estimates are written there, so the pins
   read the estimate until they are linked */
static void keep_estimates(struct __comp_state *inst)
{
    inst->cmd_d_est = inst->command_deriv;
    inst->fb_d_est = inst->feedback_deriv;
}

/* the tuner's result */
static void set_gains(struct __comp_state *inst, double p, double i,
                      double d, double ff1)
{
    *inst->Pgain = p;
    *inst->Igain = i;
    *inst->Dgain = d;
    *inst->FF1 = ff1;
}

#pragma pop_macro("command_deriv")
#pragma pop_macro("feedback_deriv")
#pragma pop_macro("Pgain")
#pragma pop_macro("Igain")
#pragma pop_macro("Dgain")
#pragma pop_macro("FF1")
#pragma pop_macro("cmd_d_est")
#pragma pop_macro("fb_d_est")

/* read bias as it is: the input pin names add 0, which turns a -0 bias
   into +0 (the reference's output is -0 then) */
#undef bias
#define bias (*__comp_inst->bias)

static inline double clamp(double v, double lim)
{
    if (lim != 0.0) {
        if (v > lim)
            return lim;
        if (v < -lim)
            return -lim;
    }
    return v;
}

/* one half cycle of the tuning oscillation has ended */
static void tune_half(struct __comp_state *__comp_inst)
{
    tcount++;
    tamp_sum += tamp;
    tamp = 0;
}

static void tune(struct __comp_state *__comp_inst, long period)
{
    double e = command - feedback;
    double effort = fabs(tune_effort);

    error = e;
    if (!enable || !tune_mode)
        tstate = T_ABORT;

    switch (tstate) {
    case T_IDLE:
        if (tune_start)
            tstate = T_START;
        break;
    case T_START:
        tstate = T_POS;
        tcount = 0;
        tperiod = 0;
        ttotal = 0;
        tamp = 0;
        tamp_sum = 0;
        if (debug) {
            ultimate_gain = 0;
            ultimate_period = 0;
        }
        output = bias + effort;
        break;
    case T_POS:
    case T_NEG:
        ttotal += period;
        if (e < 0.0) {
            if (-e > tamp)
                tamp = -e;
            if (tstate == T_POS) {
                tstate = T_NEG;
                tune_half(__comp_inst);
            }
            output = bias - effort;
        } else {
            if (e > tamp)
                tamp = e;
            if (tstate == T_NEG) {
                tstate = T_POS;
                tune_half(__comp_inst);
            }
            output = bias + effort;
        }
        if (tcount >= (int)tune_cycles) {
            /* Ziegler-Nichols from the relay oscillation */
            double amp = tamp_sum / tcount;
            double ku = 4.0 * effort / (M_PI * amp);
            double tu = ttotal * 1e-9 / (tcount / 2.0);
            double p;
            if (debug) {
                ultimate_gain = ku;
                ultimate_period = tu;
            }
            if (tune_type == 0) {
                p = 0.6 * ku;
                set_gains(__comp_inst, p, 2.0 * p / tu, p * tu / 8.0, FF1);
            } else {
                /* PI rule; FF1 = 1 takes the velocity feed-forward */
                p = 0.45 * ku;
                set_gains(__comp_inst, p, 1.2 * p / tu, 0, 1);
            }
            output = bias;
            tune_start = 0;
            tstate = T_IDLE;
        }
        break;
    default:
        output = bias;
        tune_start = 0;
        tstate = tune_mode ? T_IDLE : T_OFF;
    }
}

FUNCTION(do_pid_calcs)
{
    double T, rT, cmd, fb, e, o, cd, fd, d1, d2;
    int en, hold;

    if (tstate != T_OFF) {
        tune(__comp_inst, period);
        return;
    }

    T = period * 1e-9;
    rT = 1.0 / T;
    en = enable;
    cmd = command;
    fb = feedback;
    /* on the falling edge of index-enable the position has just been
       rebased: the previous command and the estimates do not apply */
    hold = prev_ie && !index_enable;

    if (!hold && error_previous_target)
        e = prev_cmd - fb;
    else
        e = cmd - fb;
    error = e;
    if (tune_mode) {
        /* entering tune mode: the tuner takes over from the next period;
           the loop starts afresh when it comes back */
        output = 0;
        ei = 0;
        err_d = 0;
        prev_cmd = 0;
        /* the command derivatives start from 0 again too */
        cmd_d = 0;
        cmd_dd = 0;
        cmd_ddd = 0;
        if (debug) {
            errorI = 0;
            errorD = 0;
            commandD = 0;
            commandDD = 0;
            commandDDD = 0;
        }
        tstate = T_IDLE;
        return;
    }

    e = clamp(e, maxerror);
    if (e > deadband)
        e -= deadband;
    else if (e < -deadband)
        e += deadband;
    else
        e = 0;

    if (en) {
        /* no wind-up: hold the integral while the output is clamped and
           the error pushes it further into the limit */
        if (e * limit_dir <= 0)
            ei += e * T;
        ei = clamp(ei, maxerrorI);
    } else {
        ei = 0;
    }

    if (!hold) {
        *cmd_d_est = (cmd - prev_cmd) * rT;
        *fb_d_est = (fb - prev_fb) * rT;
    }
    cd = command_deriv;
    fd = feedback_deriv;

    err_d = clamp(cd - fd, maxerrorD);
    d1 = cmd_d;
    d2 = cmd_dd;
    cmd_d = clamp(cd, maxcmdD);
    cmd_dd = clamp((cmd_d - d1) * rT, maxcmdDD);
    cmd_ddd = clamp((cmd_dd - d2) * rT, maxcmdDDD);

    prev_cmd = cmd;
    prev_fb = fb;
    prev_ie = index_enable;

    if (en) {
        o = bias + Pgain * e + Igain * ei + Dgain * err_d + FF0 * cmd
            + FF1 * cmd_d + FF2 * cmd_dd + FF3 * cmd_ddd;
    } else {
        /* disabled: the output is zero and not saturated, whatever
           maxoutput is (even a negative one, which would clamp 0) */
        o = 0;
        limit_dir = 0;
    }

    if (en && maxoutput != 0.0) {
        limit_dir = 0;
        if (o > maxoutput) {
            o = maxoutput;
            limit_dir = 1;
        } else if (o < -maxoutput) {
            o = -maxoutput;
            limit_dir = -1;
        }
    }
    output = o;

    if (limit_dir) {
        saturated = 1;
        saturated_s += T;
        saturated_count++;
    } else {
        saturated = 0;
        saturated_s = 0;
        saturated_count = 0;
    }

    if (debug) {
        errorI = ei;
        errorD = err_d;
        commandD = cmd_d;
        commandDD = cmd_dd;
        commandDDD = cmd_ddd;
    }
}

int rtapi_app_main(void)
{
    char buf[HAL_NAME_LEN + 1];
    int n, r;

    if (num_chan && names[0]) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "num_chan= and names= are mutually exclusive\n");
        return -EINVAL;
    }
    if (!names[0]) {
        if (!num_chan)
            num_chan = 3;
        if (num_chan < 1 || num_chan > MAX_CHAN) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "PID: ERROR: invalid number of channels: %d\n",
                            num_chan);
            return -EPERM;
        }
    }

    comp_id = hal_init("pid");
    if (comp_id < 0)
        return comp_id;

    if (names[0]) {
        for (n = 0; n < MAX_CHAN && names[n] && names[n][0]; n++) {
            r = export(names[n], n, 0);
            if (r != 0)
                goto fail;
            keep_estimates(__comp_last_inst);
        }
    } else {
        for (n = 0; n < num_chan; n++) {
            rtapi_snprintf(buf, sizeof(buf), "pid.%d", n);
            r = export(buf, n, 0);
            if (r != 0)
                goto fail;
            keep_estimates(__comp_last_inst);
        }
    }
    hal_ready(comp_id);
    return 0;

fail:
    hal_exit(comp_id);
    return r;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
