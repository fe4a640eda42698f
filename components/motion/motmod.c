/*
 * motmod.c - the motion module: loading, modparams, pins and params.
 *
 * `loadrt motmod [num_joints=N] ...` checks its modparams, finds the
 * kinematics, homing and trajectory planner modules (they must be loaded
 * first), creates the threads, the functions motion-command-handler and
 * motion-controller, the pins and params of motion(9), and the shared
 * block MOT_CHANNEL_NAME (channel.h) that clients command it through.
 * A refusal prints one clear line and leaves nothing behind.
 *
 * The command handler is in mot_command.c, the servo cycle in
 * mot_control.c.
 */
#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_string.h"
#include "hal.h"
#include "halsdk_api.h"

#include <errno.h>
#include <string.h>
#include <stdio.h>

#include "mot_priv.h"

MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("motion controller");
MODULE_LICENSE("GPL");

static int base_period_nsec = 0;
RTAPI_MP_INT(base_period_nsec,
             "fastest thread period (ns); 0: no base thread");
static int base_thread_fp = 0;
RTAPI_MP_INT(base_thread_fp, "floating point in the base thread (0/1)");
static int servo_period_nsec = 1000000;
RTAPI_MP_INT(servo_period_nsec, "servo thread period (ns)");
static int traj_period_nsec = 0;
RTAPI_MP_INT(traj_period_nsec,
             "trajectory planner period (ns); 0: servo period");
static int num_joints = 3;
RTAPI_MP_INT(num_joints, "number of joints (1..16)");
static int num_dio = 4;
RTAPI_MP_INT(num_dio, "number of digital inputs/outputs (1..64)");
static int num_aio = 4;
RTAPI_MP_INT(num_aio, "number of analog inputs/outputs (1..64)");
static int num_misc_error = 0;
RTAPI_MP_INT(num_misc_error, "number of misc error inputs (0..64)");
static int num_spindles = 1;
RTAPI_MP_INT(num_spindles, "number of spindles (1..8)");
static int unlock_joints_mask = 0;
RTAPI_MP_INT(unlock_joints_mask, "joints with unlock pins (bit 0: joint 0)");
static int num_extrajoints = 0;
RTAPI_MP_INT(num_extrajoints,
             "extra joints, not used by kinematics (0..num_joints)");

/* the state of this module.  Loading and unloading use it, and so do the
   planner hooks below: tp_hooks_t callbacks carry no context argument.
   Everything else gets it as an argument (the HAL functions as their
   arg). */
static mot_t *mot;

static int comp_id = -1;
static int made_servo_thread, made_base_thread;
static int planners_made;

static const char axis_letters[MOT_MAX_AXES] = "xyzabcuvw";

/* ---- pin helpers: stop at the first failure, keep its code ---- */
static int perr;

#define PIN(kind, dir, ptr, ...)                                          \
    do {                                                                  \
        if (perr == 0)                                                    \
            perr = hal_pin_##kind##_newf(dir, ptr, comp_id, __VA_ARGS__); \
    } while (0)

#define PARAM(kind, dir, ptr, ...)                                        \
    do {                                                                  \
        if (perr == 0)                                                    \
            perr = hal_param_##kind##_newf(dir, ptr, comp_id,             \
                                           __VA_ARGS__);                  \
    } while (0)

static void make_joint_pins(int n)
{
    mot_joint_pins_t *p = &mot->jp[n];

    PIN(float, HAL_OUT, &p->acc_cmd, "joint.%d.acc-cmd", n);
    PIN(bit, HAL_OUT, &p->active, "joint.%d.active", n);
    PIN(bit, HAL_OUT, &p->amp_enable_out, "joint.%d.amp-enable-out", n);
    PIN(bit, HAL_IN, &p->amp_fault_in, "joint.%d.amp-fault-in", n);
    PIN(float, HAL_OUT, &p->backlash_corr, "joint.%d.backlash-corr", n);
    PIN(float, HAL_OUT, &p->backlash_filt, "joint.%d.backlash-filt", n);
    PIN(float, HAL_OUT, &p->backlash_vel, "joint.%d.backlash-vel", n);
    PIN(float, HAL_OUT, &p->coarse_pos_cmd, "joint.%d.coarse-pos-cmd", n);
    PIN(bit, HAL_OUT, &p->error, "joint.%d.error", n);
    PIN(float, HAL_OUT, &p->f_error, "joint.%d.f-error", n);
    PIN(float, HAL_OUT, &p->f_error_lim, "joint.%d.f-error-lim", n);
    PIN(bit, HAL_OUT, &p->f_errored, "joint.%d.f-errored", n);
    PIN(bit, HAL_OUT, &p->faulted, "joint.%d.faulted", n);
    PIN(float, HAL_OUT, &p->free_pos_cmd, "joint.%d.free-pos-cmd", n);
    PIN(bit, HAL_OUT, &p->free_tp_enable, "joint.%d.free-tp-enable", n);
    PIN(float, HAL_OUT, &p->free_vel_lim, "joint.%d.free-vel-lim", n);
    PIN(bit, HAL_OUT, &p->in_position, "joint.%d.in-position", n);
    PIN(float, HAL_IN, &p->jog_accel_fraction,
        "joint.%d.jog-accel-fraction", n);
    PIN(s32, HAL_IN, &p->jog_counts, "joint.%d.jog-counts", n);
    PIN(bit, HAL_IN, &p->jog_enable, "joint.%d.jog-enable", n);
    PIN(float, HAL_IN, &p->jog_scale, "joint.%d.jog-scale", n);
    PIN(bit, HAL_IN, &p->jog_vel_mode, "joint.%d.jog-vel-mode", n);
    PIN(bit, HAL_OUT, &p->kb_jog_active, "joint.%d.kb-jog-active", n);
    PIN(float, HAL_OUT, &p->motor_offset, "joint.%d.motor-offset", n);
    PIN(float, HAL_OUT, &p->motor_pos_cmd, "joint.%d.motor-pos-cmd", n);
    PIN(float, HAL_IN, &p->motor_pos_fb, "joint.%d.motor-pos-fb", n);
    PIN(bit, HAL_OUT, &p->neg_hard_limit, "joint.%d.neg-hard-limit", n);
    PIN(bit, HAL_IN, &p->neg_lim_sw_in, "joint.%d.neg-lim-sw-in", n);
    PIN(float, HAL_OUT, &p->pos_cmd, "joint.%d.pos-cmd", n);
    PIN(float, HAL_OUT, &p->pos_fb, "joint.%d.pos-fb", n);
    PIN(bit, HAL_OUT, &p->pos_hard_limit, "joint.%d.pos-hard-limit", n);
    PIN(bit, HAL_IN, &p->pos_lim_sw_in, "joint.%d.pos-lim-sw-in", n);
    PIN(float, HAL_OUT, &p->vel_cmd, "joint.%d.vel-cmd", n);
    PIN(bit, HAL_OUT, &p->wheel_jog_active, "joint.%d.wheel-jog-active", n);
    if (mot->unlock_mask & (1u << n)) {
        PIN(bit, HAL_OUT, &p->unlock, "joint.%d.unlock", n);
        PIN(bit, HAL_IN, &p->is_unlocked, "joint.%d.is-unlocked", n);
    }
    if (n >= mot->num_joints - mot->num_extra)
        PIN(float, HAL_IN, &p->posthome_cmd, "joint.%d.posthome-cmd", n);
    if (perr == 0)
        *p->jog_accel_fraction = 1.0;
}

static void make_axis_pins(int n)
{
    mot_axis_pins_t *p = &mot->ap[n];
    char c = axis_letters[n];

    PIN(float, HAL_OUT, &p->eoffset, "axis.%c.eoffset", c);
    PIN(bit, HAL_IN, &p->eoffset_clear, "axis.%c.eoffset-clear", c);
    PIN(s32, HAL_IN, &p->eoffset_counts, "axis.%c.eoffset-counts", c);
    PIN(bit, HAL_IN, &p->eoffset_enable, "axis.%c.eoffset-enable", c);
    PIN(float, HAL_OUT, &p->eoffset_request, "axis.%c.eoffset-request", c);
    PIN(float, HAL_IN, &p->eoffset_scale, "axis.%c.eoffset-scale", c);
    PIN(float, HAL_IN, &p->jog_accel_fraction,
        "axis.%c.jog-accel-fraction", c);
    PIN(s32, HAL_IN, &p->jog_counts, "axis.%c.jog-counts", c);
    PIN(bit, HAL_IN, &p->jog_enable, "axis.%c.jog-enable", c);
    PIN(float, HAL_IN, &p->jog_scale, "axis.%c.jog-scale", c);
    PIN(bit, HAL_IN, &p->jog_vel_mode, "axis.%c.jog-vel-mode", c);
    PIN(bit, HAL_OUT, &p->kb_jog_active, "axis.%c.kb-jog-active", c);
    PIN(float, HAL_OUT, &p->pos_cmd, "axis.%c.pos-cmd", c);
    PIN(float, HAL_OUT, &p->teleop_pos_cmd, "axis.%c.teleop-pos-cmd", c);
    PIN(bit, HAL_OUT, &p->teleop_tp_enable, "axis.%c.teleop-tp-enable", c);
    PIN(float, HAL_OUT, &p->teleop_vel_cmd, "axis.%c.teleop-vel-cmd", c);
    PIN(float, HAL_OUT, &p->teleop_vel_lim, "axis.%c.teleop-vel-lim", c);
    PIN(bit, HAL_OUT, &p->wheel_jog_active, "axis.%c.wheel-jog-active", c);
    if (perr == 0)
        *p->jog_accel_fraction = 1.0;
}

static void make_spindle_pins(int n)
{
    mot_spindle_pins_t *p = &mot->sp[n];

    PIN(bit, HAL_IN, &p->amp_fault_in, "spindle.%d.amp-fault-in", n);
    PIN(bit, HAL_IN, &p->at_speed, "spindle.%d.at-speed", n);
    PIN(bit, HAL_OUT, &p->brake, "spindle.%d.brake", n);
    PIN(bit, HAL_OUT, &p->forward, "spindle.%d.forward", n);
    PIN(bit, HAL_IO, &p->index_enable, "spindle.%d.index-enable", n);
    PIN(bit, HAL_IN, &p->inhibit, "spindle.%d.inhibit", n);
    PIN(bit, HAL_IN, &p->is_oriented, "spindle.%d.is-oriented", n);
    PIN(bit, HAL_OUT, &p->locked, "spindle.%d.locked", n);
    PIN(bit, HAL_OUT, &p->on, "spindle.%d.on", n);
    PIN(bit, HAL_OUT, &p->orient, "spindle.%d.orient", n);
    PIN(float, HAL_OUT, &p->orient_angle, "spindle.%d.orient-angle", n);
    PIN(s32, HAL_IN, &p->orient_fault, "spindle.%d.orient-fault", n);
    PIN(s32, HAL_OUT, &p->orient_mode, "spindle.%d.orient-mode", n);
    PIN(bit, HAL_OUT, &p->reverse, "spindle.%d.reverse", n);
    PIN(float, HAL_IN, &p->revs, "spindle.%d.revs", n);
    PIN(float, HAL_OUT, &p->speed_cmd_rps, "spindle.%d.speed-cmd-rps", n);
    PIN(float, HAL_IN, &p->speed_in, "spindle.%d.speed-in", n);
    PIN(float, HAL_OUT, &p->speed_out, "spindle.%d.speed-out", n);
    PIN(float, HAL_OUT, &p->speed_out_abs, "spindle.%d.speed-out-abs", n);
    PIN(float, HAL_OUT, &p->speed_out_rps, "spindle.%d.speed-out-rps", n);
    PIN(float, HAL_OUT, &p->speed_out_rps_abs,
        "spindle.%d.speed-out-rps-abs", n);
    if (perr == 0)
        *p->at_speed = 1;
}

static void make_motion_pins(void)
{
    mot_motion_pins_t *p = mot->mp;
    mot_params_t *q = mot->par;
    int i;

    PIN(float, HAL_IN, &p->adaptive_feed, "motion.adaptive-feed");
    for (i = 0; i < mot->num_aio; i++) {
        PIN(float, HAL_IN, &p->analog_in[i], "motion.analog-in-%02d", i);
        PIN(float, HAL_OUT, &p->analog_out[i], "motion.analog-out-%02d", i);
    }
    for (i = 0; i < mot->num_dio; i++) {
        PIN(bit, HAL_IN, &p->digital_in[i], "motion.digital-in-%02d", i);
        PIN(bit, HAL_OUT, &p->digital_out[i], "motion.digital-out-%02d", i);
    }
    for (i = 0; i < mot->num_misc; i++)
        PIN(bit, HAL_IN, &p->misc_error[i], "motion.misc-error-%02d", i);
    PIN(bit, HAL_OUT, &p->coord_error, "motion.coord-error");
    PIN(bit, HAL_OUT, &p->coord_mode, "motion.coord-mode");
    PIN(float, HAL_OUT, &p->current_vel, "motion.current-vel");
    PIN(float, HAL_OUT, &p->distance_to_go, "motion.distance-to-go");
    PIN(bit, HAL_IN, &p->enable, "motion.enable");
    PIN(bit, HAL_OUT, &p->eoffset_active, "motion.eoffset-active");
    PIN(bit, HAL_OUT, &p->eoffset_limited, "motion.eoffset-limited");
    PIN(bit, HAL_IN, &p->feed_hold, "motion.feed-hold");
    PIN(float, HAL_OUT, &p->feed_inches_per_minute,
        "motion.feed-inches-per-minute");
    PIN(float, HAL_OUT, &p->feed_inches_per_second,
        "motion.feed-inches-per-second");
    PIN(bit, HAL_IN, &p->feed_inhibit, "motion.feed-inhibit");
    PIN(float, HAL_OUT, &p->feed_mm_per_minute, "motion.feed-mm-per-minute");
    PIN(float, HAL_OUT, &p->feed_mm_per_second, "motion.feed-mm-per-second");
    PIN(float, HAL_OUT, &p->feed_upm, "motion.feed-upm");
    PIN(bit, HAL_IN, &p->homing_inhibit, "motion.homing-inhibit");
    PIN(bit, HAL_OUT, &p->in_position, "motion.in-position");
    PIN(bit, HAL_OUT, &p->is_all_homed, "motion.is-all-homed");
    PIN(bit, HAL_IN, &p->jog_inhibit, "motion.jog-inhibit");
    PIN(bit, HAL_OUT, &p->jog_is_active, "motion.jog-is-active");
    PIN(bit, HAL_IN, &p->jog_stop, "motion.jog-stop");
    PIN(bit, HAL_IN, &p->jog_stop_immediate, "motion.jog-stop-immediate");
    PIN(bit, HAL_OUT, &p->motion_enabled, "motion.motion-enabled");
    PIN(s32, HAL_OUT, &p->motion_type, "motion.motion-type");
    PIN(bit, HAL_OUT, &p->on_soft_limit, "motion.on-soft-limit");
    PIN(bit, HAL_IN, &p->probe_input, "motion.probe-input");
    PIN(s32, HAL_OUT, &p->program_line, "motion.program-line");
    PIN(float, HAL_OUT, &p->requested_vel, "motion.requested-vel");
    PIN(u32, HAL_OUT, &p->servo_last_period, "motion.servo.last-period");
    PIN(bit, HAL_OUT, &p->teleop_mode, "motion.teleop-mode");
    for (i = 0; i < MOT_MAX_AXES; i++)
        PIN(float, HAL_OUT, &p->tooloffset[i], "motion.tooloffset.%c",
            axis_letters[i]);
    PIN(bit, HAL_OUT, &p->tp_reverse, "motion.tp-reverse");
    if (perr == 0) {
        *p->adaptive_feed = 1.0;
        *p->enable = 1;
    }

    PARAM(bit, HAL_RO, &q->debug_bit[0], "motion.debug-bit-0");
    PARAM(bit, HAL_RO, &q->debug_bit[1], "motion.debug-bit-1");
    for (i = 0; i < 4; i++)
        PARAM(float, HAL_RO, &q->debug_float[i], "motion.debug-float-%d", i);
    PARAM(s32, HAL_RO, &q->debug_s32[0], "motion.debug-s32-0");
    PARAM(s32, HAL_RO, &q->debug_s32[1], "motion.debug-s32-1");
    for (i = 0; i < 4; i++) {
        PARAM(float, HAL_RO, &q->tc_acc[i], "tc.%d.acc", i);
        PARAM(float, HAL_RO, &q->tc_pos[i], "tc.%d.pos", i);
        PARAM(float, HAL_RO, &q->tc_vel[i], "tc.%d.vel", i);
    }
    PARAM(u32, HAL_RO, &q->active_tc, "traj.active_tc");
    PARAM(float, HAL_RO, &q->pos_out, "traj.pos_out");
    PARAM(float, HAL_RO, &q->vel_out, "traj.vel_out");
}

/* synchronized outputs fired by the planner at the start of a move */
static void hook_dout(int i, int v)
{
    if (i >= 0 && i < mot->num_dio)
        *mot->mp->digital_out[i] = v ? 1 : 0;
}

static void hook_aout(int i, double v)
{
    if (i >= 0 && i < mot->num_aio)
        *mot->mp->analog_out[i] = v;
}

/* G33: arm spindle.N.index-enable; the encoder resets it at the index */
static void hook_index_enable(int n)
{
    if (n >= 0 && n < mot->num_spindles) {
        *mot->sp[n].index_enable = 1;
        mot->spindle[n].index_armed = 1;
    }
}

/* rigid tapping: turn spindle n the other way than commanded (1) or back
   (0) */
static void hook_spindle_reverse(int n, int reverse)
{
    if (n >= 0 && n < mot->num_spindles)
        mot->spindle[n].reversed = reverse ? 1 : 0;
}

static const tp_hooks_t tp_hooks = {
    .set_dout = hook_dout,
    .set_aout = hook_aout,
    .index_enable = hook_index_enable,
    .spindle_reverse = hook_spindle_reverse,
};

/* ---- modparam checks: before anything is created ---- */
static int check_range(const char *name, int v, int lo, int hi)
{
    if (v < lo || v > hi) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "motmod: %s=%d is out of range (%d..%d)\n",
                        name, v, lo, hi);
        return -EINVAL;
    }
    return 0;
}

static int check_modparams(void)
{
    if (check_range("num_joints", num_joints, 1, MOT_MAX_JOINTS)
        || check_range("num_dio", num_dio, 1, MOT_MAX_DIO)
        || check_range("num_aio", num_aio, 1, MOT_MAX_AIO)
        || check_range("num_misc_error", num_misc_error, 0,
                       MOT_MAX_MISC_ERROR)
        || check_range("num_spindles", num_spindles, 1, MOT_MAX_SPINDLES)
        || check_range("num_extrajoints", num_extrajoints, 0, num_joints)
        || check_range("base_thread_fp", base_thread_fp, 0, 1))
        return -EINVAL;
    if (servo_period_nsec <= 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: servo_period_nsec=%d must "
                        "be a positive number of nanoseconds\n",
                        servo_period_nsec);
        return -EINVAL;
    }
    if (base_period_nsec < 0 || base_period_nsec > servo_period_nsec) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: base_period_nsec=%d must "
                        "be 0 (no base thread) or a period no longer than "
                        "servo_period_nsec=%d\n", base_period_nsec,
                        servo_period_nsec);
        return -EINVAL;
    }
    if (traj_period_nsec < 0
        || (traj_period_nsec > 0 && traj_period_nsec < servo_period_nsec)) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: traj_period_nsec=%d must "
                        "be 0 (the servo period) or at least "
                        "servo_period_nsec=%d\n", traj_period_nsec,
                        servo_period_nsec);
        return -EINVAL;
    }
    if ((unsigned)unlock_joints_mask >> num_joints) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: unlock_joints_mask=0x%x "
                        "names joints beyond num_joints=%d\n",
                        (unsigned)unlock_joints_mask, num_joints);
        return -EINVAL;
    }
    return 0;
}

/* ---- the modules motmod needs ---- */
static int find_modules(void)
{
    mot->kins_fwd = (mot_kins_fwd_fn)halsdk_symbol_find("kinematicsForward");
    mot->kins_inv = (mot_kins_inv_fn)halsdk_symbol_find("kinematicsInverse");
    mot->kins_type_fn = (mot_kins_type_fn)halsdk_symbol_find("kinematicsType");
    if (!mot->kins_fwd || !mot->kins_inv || !mot->kins_type_fn) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: no kinematics module is "
                        "loaded (loadrt trivkins first)\n");
        return -ENOENT;
    }
    mot->kins_switchable =
        (mot_kins_switchable_fn)halsdk_symbol_find("kinematicsSwitchable");
    mot->kins_switch =
        (mot_kins_switch_fn)halsdk_symbol_find("kinematicsSwitch");
    mot->kins_home = (mot_kins_home_fn)halsdk_symbol_find("kinematicsHome");
    mot->kins_type = mot->kins_type_fn();

    mot->home = (const mot_homing_api_t *)
        halsdk_symbol_find(HALSDK_HOMING_SYMBOL);
    if (!mot->home) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: no homing module is loaded "
                        "(loadrt homemod first)\n");
        return -ENOENT;
    }
    if (mot->home->version != HALSDK_HOMING_VERSION) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: the homing module has "
                        "interface version %d, motmod needs %d\n",
                        mot->home->version, HALSDK_HOMING_VERSION);
        return -EINVAL;
    }
    mot->tp = (const halsdk_tp_api_t *)halsdk_symbol_find(HALSDK_TP_SYMBOL);
    if (!mot->tp) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: no trajectory planner "
                        "module is loaded (loadrt tpmod first)\n");
        return -ENOENT;
    }
    if (mot->tp->version != HALSDK_TP_VERSION) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: the trajectory planner has "
                        "interface version %d, motmod needs %d\n",
                        mot->tp->version, HALSDK_TP_VERSION);
        return -EINVAL;
    }
    if (num_extrajoints > 0 && mot->kins_type != MOT_KINS_BOTH) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: num_extrajoints=%d needs "
                        "kinematics of type BOTH (e.g. loadrt trivkins "
                        "kinstype=both)\n", num_extrajoints);
        return -EINVAL;
    }
    return 0;
}

static void cleanup(void)
{
    int i;
    if (mot && planners_made) {
        for (i = 0; i < mot->num_joints; i++)
            fp_free(&mot->joints[i].free_tp);
        for (i = 0; i < MOT_MAX_AXES; i++)
            fp_free(&mot->axis[i].tp);
        planners_made = 0;
    }
    if (made_base_thread)
        hal_thread_delete("base-thread");
    if (made_servo_thread)
        hal_thread_delete("servo-thread");
    made_base_thread = made_servo_thread = 0;
    if (comp_id >= 0)
        hal_exit(comp_id);
    comp_id = -1;
    mot = NULL;
}

static void init_state(void)
{
    int i;

    mot->mode = MOT_MODE_FREE;
    mot->profile = FP_TRAPEZOID;
    mot->feed_scale = 1.0;
    mot->rapid_scale = 1.0;
    mot->tp_feed = mot->tp_rapid = 1.0;
    mot->override_jog = -1;
    mot->tp_done = 1;
    mot->inpos = 1;
    mot->feed_hold_enabled = 1;     /* the reference's default (M53 P1) */
    mot->adaptive_enabled = 0;      /* off until M52 P1 */
    mot->adaptive_now = 1.0;
    mot->enable_pin_old = 1;
    for (i = 0; i < mot->num_joints; i++) {
        mot_joint_t *j = &mot->joints[i];
        j->index = i;
        j->flags = MOT_JOINT_ACTIVE | MOT_JOINT_INPOS;
        /* defaults until the SET_JOINT_* commands come: wide soft
           limits, the reference's INI defaults for the rest */
        j->min_pos_limit = -1e99;
        j->max_pos_limit = 1e99;
        j->vel_limit = 1.0;
        j->acc_limit = 1.0;
        j->min_ferror = 0.01;
        j->max_ferror = 1.0;
        mot->amp_on[i] = 0;
        mot->home_seq[i] = HOME_SEQUENCE_NONE;
        mot_comp_init(&mot->comp[i]);
    }
    for (i = 0; i < MOT_MAX_AXES; i++) {
        mot_axis_t *a = &mot->axis[i];
        a->min_pos_limit = -1e99;
        a->max_pos_limit = 1e99;
        a->vel_limit = 1.0;
        a->acc_limit = 1.0;
    }
}

int rtapi_app_main(void)
{
    int i, r;
    char why[MOT_REASON_LEN];

    if (check_modparams() < 0)
        return -EINVAL;

    comp_id = hal_init("motmod");
    if (comp_id < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: hal_init failed (%d)\n",
                        comp_id);
        return comp_id;
    }
    mot = hal_malloc(sizeof(*mot));
    if (!mot)
        goto nomem;
    memset(mot, 0, sizeof(*mot));
    mot->comp_id = comp_id;
    mot->num_joints = num_joints;
    mot->num_joints_used = num_joints;
    mot->num_extra = num_extrajoints;
    mot->num_dio = num_dio;
    mot->num_aio = num_aio;
    mot->num_misc = num_misc_error;
    mot->num_spindles = num_spindles;
    mot->unlock_mask = (unsigned)unlock_joints_mask;
    mot->servo_period = servo_period_nsec * 1e-9;
    if (traj_period_nsec == 0)
        traj_period_nsec = servo_period_nsec;
    mot->interp_rate = (traj_period_nsec + servo_period_nsec / 2)
                       / servo_period_nsec;
    if (mot->interp_rate < 1)
        mot->interp_rate = 1;
    mot->traj_period = mot->servo_period * mot->interp_rate;

    r = find_modules();
    if (r < 0) {
        cleanup();
        return r;
    }

    mot->joints = hal_malloc(sizeof(mot_joint_t) * num_joints);
    mot->comp = hal_malloc(sizeof(mot_comp_t) * num_joints);
    mot->jp = hal_malloc(sizeof(mot_joint_pins_t) * num_joints);
    mot->ap = hal_malloc(sizeof(mot_axis_pins_t) * MOT_MAX_AXES);
    mot->sp = hal_malloc(sizeof(mot_spindle_pins_t) * num_spindles);
    mot->mp = hal_malloc(sizeof(mot_motion_pins_t));
    mot->par = hal_malloc(sizeof(mot_params_t));
    mot->lines = hal_malloc(sizeof(*mot->lines) * MOT_LINE_FIFO);
    if (!mot->joints || !mot->comp || !mot->jp || !mot->ap || !mot->sp
        || !mot->mp || !mot->par || !mot->lines)
        goto nomem;
    memset(mot->joints, 0, sizeof(mot_joint_t) * num_joints);
    memset(mot->jp, 0, sizeof(mot_joint_pins_t) * num_joints);
    memset(mot->ap, 0, sizeof(mot_axis_pins_t) * MOT_MAX_AXES);
    memset(mot->sp, 0, sizeof(mot_spindle_pins_t) * num_spindles);
    memset(mot->mp, 0, sizeof(mot_motion_pins_t));
    memset(mot->par, 0, sizeof(mot_params_t));

    for (i = 0; i < num_joints; i++) {
        if (fp_init(&mot->joints[i].free_tp) < 0)
            goto nomem_planners;
    }
    for (i = 0; i < MOT_MAX_AXES; i++) {
        if (fp_init(&mot->axis[i].tp) < 0)
            goto nomem_planners;
    }
    planners_made = 1;
    init_state();

    /* pins and params */
    perr = 0;
    for (i = 0; i < num_joints; i++)
        make_joint_pins(i);
    for (i = 0; i < MOT_MAX_AXES; i++)
        make_axis_pins(i);
    for (i = 0; i < num_spindles; i++)
        make_spindle_pins(i);
    make_motion_pins();
    if (perr < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: creating the pins and "
                        "params failed (%d)\n", perr);
        cleanup();
        return perr;
    }

    /* homing pins and state */
    r = mot->home->init(comp_id, mot->servo_period, num_joints,
                        num_extrajoints, mot->joints);
    if (r < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: the homing module refused "
                        "to start (%d)\n", r);
        cleanup();
        return r;
    }
    /* trajectory planner */
    why[0] = 0;
    r = mot->tp->init(comp_id, mot->traj_period, &tp_hooks, why,
                      sizeof(why));
    if (r < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: the trajectory planner "
                        "refused to start: %s\n", why[0] ? why : "error");
        cleanup();
        return r;
    }

    /* the command channel */
    mot->chan_handle = HALSDK_API->shmem_new(MOT_CHANNEL_NAME, comp_id,
                                             sizeof(mot_channel_t));
    if (mot->chan_handle < 0
        || !(mot->chan = HALSDK_API->shmem_ptr(mot->chan_handle))) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: cannot create the shared "
                        "block %s (%lld)\n", MOT_CHANNEL_NAME,
                        mot->chan_handle);
        cleanup();
        return mot->chan_handle < 0 ? (int)mot->chan_handle : -ENOMEM;
    }
    mot->chan->size = sizeof(mot_channel_t);
    mot->chan->version = MOT_CHANNEL_VERSION;
    __atomic_store_n(&mot->chan->magic, MOT_CHANNEL_MAGIC, __ATOMIC_RELEASE);

    /* functions */
    /* both get the state as their arg */
    r = hal_export_funct("motion-command-handler", mot_command_handler,
                         mot, 1, 0, comp_id);
    if (r == 0)
        r = hal_export_funct("motion-controller", mot_controller, mot, 1,
                             0, comp_id);
    if (r < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: exporting the functions "
                        "failed (%d)\n", r);
        cleanup();
        return r;
    }

    /* threads */
    if (base_period_nsec > 0) {
        r = hal_create_thread("base-thread", base_period_nsec,
                              base_thread_fp);
        if (r < 0) {
            rtapi_print_msg(RTAPI_MSG_ERR, "motmod: cannot create "
                            "base-thread (%d)\n", r);
            cleanup();
            return r;
        }
        made_base_thread = 1;
    }
    r = hal_create_thread("servo-thread", servo_period_nsec, 1);
    if (r < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "motmod: cannot create servo-thread "
                        "(%d)\n", r);
        cleanup();
        return r;
    }
    made_servo_thread = 1;

    mot_sync_planners(mot);
    mot_write_status(mot);
    hal_ready(comp_id);
    return 0;

nomem_planners:
    planners_made = 1;          /* fp_free of zeroed planners is harmless */
nomem:
    rtapi_print_msg(RTAPI_MSG_ERR, "motmod: out of memory\n");
    cleanup();
    return -ENOMEM;
}

void rtapi_app_exit(void)
{
    cleanup();
}
