/*
 * mot_control.c - motion-controller, the servo-cycle function of motmod.
 *
 * Every servo period it
 *   1. reads the input pins (feedback, limit switches, amp faults, ...),
 *      computes pos_fb and the following error;
 *   2. checks for faults (motion.enable, amp faults, hard limits,
 *      following error, misc errors): any fault disables motion, turns
 *      the amplifiers off and posts a message saying why;
 *   3. runs homing (homing.h);
 *   4. runs the planners of the present mode: the joints' free planners
 *      (free mode; extra joints always), the axes' teleop planners and
 *      inverse kinematics (teleop), or the trajectory planner every
 *      interp_rate servo cycles with linear interpolation of its coarse
 *      positions to the servo rate (coord);
 *   5. adds backlash/screw compensation and the motor offset:
 *      motor_pos_cmd = pos_cmd + backlash_filt + motor_offset;
 *   6. runs the spindles (amplifier faults, the orient handshake, speed
 *      and direction outputs, CSS);
 *   7. writes the output pins and the status snapshot (seqlock).
 *
 * Feed hold (when enabled, M53), feed inhibit and adaptive feed (when
 * enabled, M52) are read once per cycle and handed to the planner with
 * its inputs (tp.h v2), with the per-spindle revs, speed, at-speed and
 * index-enable.  motion.program-line and motion.requested-vel come from
 * a list of the moves given to the planner (id, line, vel), followed by
 * the planner's exec_id.
 *
 * The seven positions of the developer manual: carte_pos_cmd (mot->
 * carte_pos_cmd), coarse_pos (joint coarse_pos: the planner's output
 * before interpolation), pos_cmd, motor_pos_cmd, motor_pos_fb (input),
 * pos_fb = motor_pos_fb - backlash_filt - motor_offset, and carte_pos_fb
 * = forward kinematics of pos_fb.  carte_pos_fb is computed when the
 * kinematics are identity or all joints are homed; with unhomed joints of
 * other kinematics it keeps its last value, and with inverse-only
 * kinematics it copies carte_pos_cmd; status.carte_pos_fb_ok is 0 in both
 * cases (a non-trivial forward transform of unhomed joints means
 * nothing).
 *
 * While motion is disabled the commanded positions follow the feedback
 * (pos_cmd = pos_fb), so that enabling never makes a step.
 */
#include "rtapi.h"
#include "rtapi_math.h"
#include "rtapi_string.h"
#include "hal.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <math.h>

#include "mot_priv.h"

/* backlash and screw compensation (mot_comp.h): the correction follows
   the direction of the commanded motion, limited to a share of the
   joint's velocity and acceleration limits */
static inline void mot_comp_joint(mot_t *mot, int n, double dt)
{
    mot_joint_t *j = &mot->joints[n];
    mot_comp_t *c = &mot->comp[n];

    if (c->backlash == 0.0 && c->entries == 0 && c->filt.pos == 0.0
        && c->filt.vel == 0.0) {
        /* nothing to compensate (the usual case): keep the direction */
        if (j->vel_cmd > 0.0)
            c->dir = 1;
        else if (j->vel_cmd < 0.0)
            c->dir = -1;
        c->corr = 0.0;
        j->backlash_corr = j->backlash_filt = j->backlash_vel = 0.0;
        return;
    }
    mot_comp_update(&mot->comp[n], j->pos_cmd, j->vel_cmd, dt,
                    j->vel_limit, j->acc_limit, &j->backlash_corr,
                    &j->backlash_filt, &j->backlash_vel);
}

/* ------------------------------------------------------------------ */

static int posthome_joint(mot_t *mot, int n);

#define HOMED(n) (mot->homed_c[(n)])
#define HOMING(n) (mot->homing_c[(n)])

/* read the homing state once per cycle */
static void refresh_home_cache(mot_t *mot)
{
    int i, all = 1, any = 0;
    for (i = 0; i < mot->num_joints; i++) {
        mot->homed_c[i] = mot->home->is_homed(i) ? 1 : 0;
        mot->homing_c[i] = mot->home->is_homing(i) ? 1 : 0;
        if (i < mot->num_joints_used && !mot->homed_c[i])
            all = 0;
        any |= mot->homing_c[i];
    }
    mot->all_homed_c = all;
    mot->any_homing_c = any;
    mot->all_homed_api_c = mot->home->all_homed() ? 1 : 0;
}

static KINEMATICS_FORWARD_FLAGS fflags;
static KINEMATICS_INVERSE_FLAGS iflags;

int mot_forward(mot_t *mot, const double *joints, EmcPose *pos)
{
    double jt[KINS_MAX_JOINTS];
    int i;
    for (i = 0; i < KINS_MAX_JOINTS; i++)
        jt[i] = i < mot->num_joints ? joints[i] : 0.0;
    return mot->kins_fwd(jt, pos, &fflags, &iflags);
}

int mot_inverse(mot_t *mot, const EmcPose *pos, double *joints)
{
    return mot->kins_inv(pos, joints, &iflags, &fflags);
}

void mot_post(mot_t *mot, const char *fmt, ...)
{
    mot_channel_t *ch = mot->chan;
    va_list ap;
    uint64_t n;
    mot_msg_t *m;

    if (!ch)
        return;
    n = ch->msg_count;
    m = &ch->msgs[n % MOT_MSG_RING];
    va_start(ap, fmt);
    vsnprintf(m->text, sizeof(m->text), fmt, ap);
    va_end(ap);
    m->n = n;
    __atomic_store_n(&ch->msg_count, n + 1, __ATOMIC_RELEASE);
    rtapi_print_msg(RTAPI_MSG_ERR, "motion: %s\n", m->text);
}

static int used_kins_joints(mot_t *mot)
{
    return mot->num_joints_used - mot->num_extra > 0
           ? mot->num_joints_used - mot->num_extra : 0;
}

static int is_extra(mot_t *mot, int j)
{
    return j >= mot->num_joints - mot->num_extra;
}

int mot_all_homed(mot_t *mot)
{
    int i;
    for (i = 0; i < mot->num_joints_used; i++)
        if (!mot->home->is_homed(i))
            return 0;
    return 1;
}

/* the carte <-> joint transforms mean something */
static int kins_valid(mot_t *mot)
{
    return mot->kins_type == KINEMATICS_IDENTITY || mot->all_homed_c;
}

int mot_moving(mot_t *mot)
{
    int i;
    for (i = 0; i < mot->num_joints_used; i++) {
        if (mot->joints[i].free_tp.active)
            return 1;
    }
    for (i = 0; i < MOT_MAX_AXES; i++)
        if (mot->axis[i].tp.active)
            return 1;
    if (mot->mode == MOT_MODE_COORD && !mot->tp_done)
        return 1;
    return 0;
}

static int profile_for(mot_t *mot, double jerk)
{
    return (mot->profile == FP_JERK && jerk > 0) ? FP_JERK : FP_TRAPEZOID;
}

void mot_joint_limits_to_planner(mot_t *mot, int n)
{
    mot_joint_t *j = &mot->joints[n];
    j->free_tp.max_acc = j->acc_limit;
    j->free_tp.max_jerk = j->jerk_limit;
    j->free_tp.profile = profile_for(mot, j->jerk_limit);
    if (j->free_tp.max_vel <= 0 || j->free_tp.max_vel > j->vel_limit)
        j->free_tp.max_vel = j->vel_limit;
}

void mot_axis_limits_to_planner(mot_t *mot, int n)
{
    mot_axis_t *a = &mot->axis[n];
    a->tp.max_acc = a->acc_limit;
    a->tp.max_jerk = a->jerk_limit;
    a->tp.profile = profile_for(mot, a->jerk_limit);
    if (a->tp.max_vel <= 0 || a->tp.max_vel > a->vel_limit)
        a->tp.max_vel = a->vel_limit;
}

/* every planner at rest where the machine is now */
/* carte_pos_cmd from the joints' pos_cmd, when the forward kinematics
   can be trusted (otherwise it keeps its value) */
static void carte_cmd_from_joints(mot_t *mot)
{
    double jt[MOT_MAX_JOINTS];
    EmcPose p;
    int i;

    if (!kins_valid(mot))
        return;
    for (i = 0; i < mot->num_joints; i++)
        jt[i] = mot->joints[i].pos_cmd;
    if (mot_forward(mot, jt, &p) == 0)
        mot->carte_pos_cmd = p;
}

void mot_sync_planners(mot_t *mot)
{
    int i;

    for (i = 0; i < mot->num_joints; i++) {
        mot_joint_t *j = &mot->joints[i];
        fp_reset(&j->free_tp, j->pos_cmd);
        mot_joint_limits_to_planner(mot, i);
        j->coarse_pos = j->pos_cmd;
        j->vel_cmd = j->acc_cmd = 0.0;
        mot->jog_kind[i] = MOT_JOG_NONE;
    }
    carte_cmd_from_joints(mot);
    for (i = 0; i < MOT_MAX_AXES; i++) {
        fp_reset(&mot->axis[i].tp, *emcpose_axis(&mot->carte_pos_cmd, i));
        mot_axis_limits_to_planner(mot, i);
        mot->axis[i].jog = MOT_JOG_NONE;
        mot->axis[i].vel_cmd = 0.0;
    }
    mot->coarse_prev = mot->coarse_next = mot->carte_pos_cmd;
    mot->traj_count = 0;
}

static void end_override_if(mot_t *mot, int who)
{
    if (mot->override_limits && mot->override_jog == who) {
        mot->override_limits = 0;
        mot->override_jog = -1;
    }
}

void mot_disable(mot_t *mot)
{
    int i;

    if (mot->home)
        mot->home->abort();
    for (i = 0; i < mot->num_joints; i++)
        mot->homing_c[i] = 0;
    mot->any_homing_c = 0;
    if (mot->tp) {
        if (mot->tp->reset)
            mot->tp->reset();
        else
            mot->tp->abort();
    }
    mot_line_clear(mot);
    mot_queue_drop(mot);
    mot_spindles_stop(mot);
    mot->enabled = 0;
    for (i = 0; i < mot->num_joints; i++)
        mot->amp_on[i] = 0;
    mot_sync_planners(mot);
    /* the jog that ends an override ended now */
    if (mot->override_jog >= 0) {
        mot->override_limits = 0;
        mot->override_jog = -1;
    }
}

static void fault(mot_t *mot)
{
    mot->error = 1;
    mot_disable(mot);
}

/* ------------------------------------------------------------------ */

static void read_inputs(mot_t *mot)
{
    int i;
    for (i = 0; i < mot->num_joints; i++) {
        mot_joint_t *j = &mot->joints[i];
        mot_joint_pins_t *p = &mot->jp[i];
        j->motor_pos_fb = *p->motor_pos_fb;
        j->pos_fb = j->motor_pos_fb - j->backlash_filt - j->motor_offset;
        j->ferror = j->pos_cmd - j->pos_fb;
        j->pos_limit_sw = *p->pos_lim_sw_in ? 1 : 0;
        j->neg_limit_sw = *p->neg_lim_sw_in ? 1 : 0;
        j->flags &= ~(MOT_JOINT_POS_HARD | MOT_JOINT_NEG_HARD
                      | MOT_JOINT_FAULT);
        if (j->pos_limit_sw)
            j->flags |= MOT_JOINT_POS_HARD;
        if (j->neg_limit_sw)
            j->flags |= MOT_JOINT_NEG_HARD;
        if (*p->amp_fault_in)
            j->flags |= MOT_JOINT_FAULT;
        if (fabs(j->ferror) > j->ferror_high_mark)
            j->ferror_high_mark = fabs(j->ferror);
    }
}

static double ferror_limit(const mot_joint_t *j)
{
    double lo = j->min_ferror, hi = j->max_ferror, f;
    if (hi < lo)
        hi = lo;
    f = j->vel_limit > 0 ? fabs(j->vel_cmd) / j->vel_limit : 1.0;
    if (f > 1.0)
        f = 1.0;
    return lo + (hi - lo) * f;
}

/* returns 1 when a fault disabled motion */
static int check_faults(mot_t *mot)
{
    int i;
    mot_motion_pins_t *mp = mot->mp;

    if (!mot->enabled)
        return 0;
    if (!*mp->enable) {
        mot_post(mot, "motion.enable went false: motion disabled");
        fault(mot);
        return 1;
    }
    for (i = 0; i < mot->num_misc; i++) {
        if (*mp->misc_error[i]) {
            mot_post(mot, "motion.misc-error-%02d is true: motion disabled",
                     i);
            fault(mot);
            return 1;
        }
    }
    for (i = 0; i < mot->num_joints_used; i++) {
        mot_joint_t *j = &mot->joints[i];
        if (!(j->flags & MOT_JOINT_ACTIVE))
            continue;
        if (j->flags & MOT_JOINT_FAULT) {
            j->flags |= MOT_JOINT_ERROR;
            mot_post(mot, "amplifier fault on joint %d: motion disabled", i);
            fault(mot);
            return 1;
        }
        if ((j->pos_limit_sw || j->neg_limit_sw) && !mot->override_limits
            && !mot->home->ignores_limits(i)) {
            j->flags |= MOT_JOINT_ERROR;
            mot_post(mot, "joint %d on %s hard limit: motion disabled", i,
                     j->pos_limit_sw ? "positive" : "negative");
            fault(mot);
            return 1;
        }
        j->ferror_limit = ferror_limit(j);
        if (fabs(j->ferror) > j->ferror_limit && !posthome_joint(mot, i)) {
            j->flags |= MOT_JOINT_ERROR | MOT_JOINT_FERROR;
            mot_post(mot, "joint %d following error: %.6g exceeds the limit "
                     "%.6g: motion disabled", i, fabs(j->ferror),
                     j->ferror_limit);
            fault(mot);
            return 1;
        }
    }
    return 0;
}

/* soft limits apply to a homed joint */
static double clamp_joint(mot_t *mot, int n, double t)
{
    mot_joint_t *j = &mot->joints[n];
    if (!HOMED(n))
        return t;
    if (t > j->max_pos_limit)
        t = j->max_pos_limit;
    if (t < j->min_pos_limit)
        t = j->min_pos_limit;
    return t;
}

static double clamp_axis(mot_t *mot, int n, double t)
{
    mot_axis_t *a = &mot->axis[n];
    if (!kins_valid(mot) || mot->kins_type == KINEMATICS_IDENTITY) {
        /* identity kins: the joints' soft limits guard the axes too */
        if (!mot->all_homed_c)
            return t;
    }
    if (t > a->max_pos_limit)
        t = a->max_pos_limit;
    if (t < a->min_pos_limit)
        t = a->min_pos_limit;
    return t;
}

/* jog wheel of joint n (free mode) */
static void wheel_joint(mot_t *mot, int n)
{
    mot_joint_t *j = &mot->joints[n];
    mot_joint_pins_t *p = &mot->jp[n];
    int counts = *p->jog_counts, delta;
    double t, frac;

    delta = counts - mot->old_counts[n];
    mot->old_counts[n] = counts;
    if (!mot->wheel_seen[n]) {          /* first cycle: no jump */
        mot->wheel_seen[n] = 1;
        return;
    }
    if (!*p->jog_enable || !mot->enabled || mot->mode != MOT_MODE_FREE
        || HOMING(n) || *mot->mp->jog_inhibit) {
        return;
    }
    if (delta == 0) {
        if (*p->jog_vel_mode && mot->jog_kind[n] == MOT_JOG_WHEEL)
            j->free_tp.enable = 0;      /* wheel stopped: stop */
        return;
    }
    t = (mot->jog_kind[n] == MOT_JOG_WHEEL && j->free_tp.enable)
        ? j->free_tp.target : j->pos_cmd;
    t = clamp_joint(mot, n, t + delta * *p->jog_scale);
    frac = *p->jog_accel_fraction;
    if (!(frac > 0) || frac > 1)
        frac = 1;
    j->free_tp.target = t;
    j->free_tp.max_vel = j->vel_limit;
    j->free_tp.max_acc = j->acc_limit * frac;
    j->free_tp.enable = 1;
    mot->jog_kind[n] = MOT_JOG_WHEEL;
}

static void wheel_axis(mot_t *mot, int n)
{
    mot_axis_t *a = &mot->axis[n];
    mot_axis_pins_t *p = &mot->ap[n];
    int counts = *p->jog_counts, delta;
    double t, frac;

    delta = counts - a->old_counts;
    a->old_counts = counts;
    if (!a->wheel_seen) {
        a->wheel_seen = 1;
        return;
    }
    if (!*p->jog_enable || !mot->enabled || mot->mode != MOT_MODE_TELEOP
        || *mot->mp->jog_inhibit)
        return;
    if (delta == 0) {
        if (*p->jog_vel_mode && a->jog == MOT_JOG_WHEEL)
            a->tp.enable = 0;
        return;
    }
    t = (a->jog == MOT_JOG_WHEEL && a->tp.enable) ? a->tp.target
        : a->tp.pos;
    t = clamp_axis(mot, n, t + delta * *p->jog_scale);
    frac = *p->jog_accel_fraction;
    if (!(frac > 0) || frac > 1)
        frac = 1;
    a->tp.target = t;
    a->tp.max_vel = a->vel_limit;
    a->tp.max_acc = a->acc_limit * frac;
    a->tp.enable = 1;
    a->jog = MOT_JOG_WHEEL;
}

/* run joint n's free planner one cycle; pos/vel/acc commands follow */
/* a homed extra joint: its command comes from joint.N.posthome-cmd
   (motion(9)); its feedback is not used */
static int posthome_joint(mot_t *mot, int n)
{
    return mot->jp[n].posthome_cmd && HOMED(n)
           && !HOMING(n);
}

static void run_free_joint(mot_t *mot, int n, double dt)
{
    mot_joint_t *j = &mot->joints[n];
    double old = j->pos_cmd, oldv = j->vel_cmd;

    if (posthome_joint(mot, n)) {
        double p = *mot->jp[n].posthome_cmd;
        if (!isfinite(p))
            p = old;
        j->pos_cmd = j->coarse_pos = p;
        j->vel_cmd = (p - old) / dt;
        j->acc_cmd = (j->vel_cmd - oldv) / dt;
        fp_reset(&j->free_tp, p);
        mot->jog_kind[n] = MOT_JOG_NONE;
        return;
    }

    wheel_joint(mot, n);
    if (*mot->mp->jog_stop_immediate && mot->jog_kind[n] != MOT_JOG_NONE) {
        fp_reset(&j->free_tp, j->free_tp.pos);
    } else if ((*mot->mp->jog_stop || *mot->mp->jog_inhibit)
               && mot->jog_kind[n] != MOT_JOG_NONE) {
        j->free_tp.enable = 0;
    }
    if (mot->jp[n].unlock) {
        /* a locking joint (unlock_joints_mask): ask for the unlock while
           it has somewhere to go, and hold it until it is unlocked */
        int want = j->free_tp.active
                   || (j->free_tp.enable
                       && j->free_tp.target != j->free_tp.pos);
        *mot->jp[n].unlock = want;
        if (want && !j->free_tp.active && !*mot->jp[n].is_unlocked) {
            j->vel_cmd = j->acc_cmd = 0.0;
            return;
        }
    }
    fp_update(&j->free_tp, dt);
    j->pos_cmd = j->free_tp.pos;
    /* a homed joint never passes a soft limit its target respects (not
       even by a rounding error of the planner) */
    if (HOMED(n) && !HOMING(n)) {
        if (j->pos_cmd > j->max_pos_limit && old <= j->max_pos_limit
            && j->free_tp.target <= j->max_pos_limit)
            j->pos_cmd = j->max_pos_limit;
        if (j->pos_cmd < j->min_pos_limit && old >= j->min_pos_limit
            && j->free_tp.target >= j->min_pos_limit)
            j->pos_cmd = j->min_pos_limit;
    }
    j->coarse_pos = j->pos_cmd;
    j->vel_cmd = (j->pos_cmd - old) / dt;
    j->acc_cmd = (j->vel_cmd - oldv) / dt;
    if (mot->jog_kind[n] != MOT_JOG_NONE && !j->free_tp.active) {
        mot->jog_kind[n] = MOT_JOG_NONE;
        end_override_if(mot, n);
    }
}

static void set_joint_cmds(mot_t *mot, const double *pos, double dt)
{
    int i, nk = used_kins_joints(mot);
    for (i = 0; i < nk; i++) {
        mot_joint_t *j = &mot->joints[i];
        double v = (pos[i] - j->pos_cmd) / dt;
        j->acc_cmd = (v - j->vel_cmd) / dt;
        j->vel_cmd = v;
        j->pos_cmd = pos[i];
        /* the free planner stays where the joint is, for FREE later */
        fp_reset(&j->free_tp, j->pos_cmd);
    }
}

static void run_teleop(mot_t *mot, double dt)
{
    int i, nk = used_kins_joints(mot);
    EmcPose p;
    double jt[KINS_MAX_JOINTS];

    for (i = 0; i < MOT_MAX_AXES; i++) {
        mot_axis_t *a = &mot->axis[i];
        double old = a->tp.pos;
        wheel_axis(mot, i);
        if (*mot->mp->jog_stop_immediate && a->jog != MOT_JOG_NONE)
            fp_reset(&a->tp, a->tp.pos);
        else if ((*mot->mp->jog_stop || *mot->mp->jog_inhibit)
                 && a->jog != MOT_JOG_NONE)
            a->tp.enable = 0;
        fp_update(&a->tp, dt);
        a->vel_cmd = (a->tp.pos - old) / dt;
        if (a->jog != MOT_JOG_NONE && !a->tp.active) {
            a->jog = MOT_JOG_NONE;
            end_override_if(mot, 100 + i);
        }
        *emcpose_axis(&p, i) = a->tp.pos;
    }
    for (i = 0; i < KINS_MAX_JOINTS; i++)
        jt[i] = i < mot->num_joints ? mot->joints[i].pos_cmd : 0.0;
    if (mot_inverse(mot, &p, jt) != 0) {
        mot_post(mot, "teleop: inverse kinematics failed at the commanded "
                 "position: motion disabled");
        fault(mot);
        return;
    }
    for (i = 0; i < nk; i++) {
        mot_joint_t *j = &mot->joints[i];
        if (!isfinite(jt[i])) {
            mot_post(mot, "teleop: inverse kinematics gave joint %d no valid "
                     "position: motion disabled", i);
            fault(mot);
            return;
        }
        if (HOMED(i)
            && ((jt[i] > j->max_pos_limit && jt[i] > j->pos_cmd)
                || (jt[i] < j->min_pos_limit && jt[i] < j->pos_cmd))) {
            /* stop where we are: a joint would leave its range */
            int k;
            mot_post(mot, "teleop move stopped: joint %d would pass its %s "
                     "soft limit", i,
                     jt[i] > j->max_pos_limit ? "positive" : "negative");
            for (k = 0; k < MOT_MAX_AXES; k++) {
                fp_reset(&mot->axis[k].tp,
                         *emcpose_axis(&mot->carte_pos_cmd, k));
                mot->axis[k].jog = MOT_JOG_NONE;
                mot->axis[k].vel_cmd = 0;
            }
            for (k = 0; k < nk; k++) {
                mot->joints[k].vel_cmd = 0;
                mot->joints[k].acc_cmd = 0;
            }
            return;
        }
    }
    mot->carte_pos_cmd = p;
    set_joint_cmds(mot, jt, dt);
    for (i = 0; i < nk; i++)
        mot->joints[i].coarse_pos = mot->joints[i].pos_cmd;
}

void mot_line_clear(mot_t *mot)
{
    mot->line_head = mot->line_count = 0;
    mot->program_line = 0;
    mot->move_req_vel = 0.0;
}

void mot_line_push(mot_t *mot, int id, int line, double vel)
{
    if (mot->line_count == MOT_LINE_FIFO) {     /* forget the oldest */
        mot->line_head = (mot->line_head + 1) % MOT_LINE_FIFO;
        mot->line_count--;
    }
    mot->lines[(mot->line_head + mot->line_count) % MOT_LINE_FIFO] =
        (struct mot_line){ id, line, vel };
    mot->line_count++;
}

/* follow the planner's exec_id through the remembered moves: the line
   and requested velocity of the move that runs (merged or skipped moves
   are passed over, up to 256 at a time) */
static void line_track(mot_t *mot, const tp_state_t *st)
{
    int k;

    if (st->done && st->queue_depth == 0) {
        mot_line_clear(mot);
        return;
    }
    for (k = 0; k < mot->line_count && k < 256; k++) {
        struct mot_line *e =
            &mot->lines[(mot->line_head + k) % MOT_LINE_FIFO];
        if (e->id == st->exec_id) {
            mot->line_head = (mot->line_head + k) % MOT_LINE_FIFO;
            mot->line_count -= k;
            mot->program_line = e->line;
            mot->move_req_vel = e->vel;
            return;
        }
    }
}

static void run_coord(mot_t *mot, double dt)
{
    int i, nk = used_kins_joints(mot);
    double jt[KINS_MAX_JOINTS], frac;
    EmcPose p;
    const halsdk_tp_api_t *tp = mot->tp;
    const char *e;

    /* overrides: feed scale x adaptive feed (when enabled); feed hold
       (when enabled) and feed inhibit stop the planner along its path
       (scale 0) */
    {
        double f = mot->feed_scale, r = mot->rapid_scale;
        if (f != mot->tp_feed || r != mot->tp_rapid) {
            mot->tp_feed = f;
            mot->tp_rapid = r;
            tp->set_scale(f, r);
        }
    }
    if (mot->traj_count == 0) {
        tp_inputs_t in;
        tp_state_t st;
        EmcPose pr;
        int r;

        memset(&in, 0, sizeof(in));
        in.probe_input = *mot->mp->probe_input ? 1 : 0;
        in.spindle_revs = *mot->sp[0].revs;
        in.spindle_speed = *mot->sp[0].speed_in;
        in.spindle_at_speed = *mot->sp[0].at_speed ? 1 : 0;
        in.have = TP_IN_FEED | TP_IN_SPINDLES;
        in.feed_hold = mot->feed_hold_now;
        in.feed_inhibit = mot->feed_inhibit_now;
        in.adaptive_feed = mot->adaptive_now;
        for (i = 0; i < mot->num_spindles && i < TP_MAX_SPINDLES; i++) {
            in.spindle[i].revs = *mot->sp[i].revs;
            in.spindle[i].speed = *mot->sp[i].speed_in;
            in.spindle[i].at_speed = *mot->sp[i].at_speed ? 1 : 0;
            in.spindle[i].index_enable = *mot->sp[i].index_enable ? 1 : 0;
        }
        mot->coarse_prev = mot->coarse_next;
        tp->run_cycle(&in, &mot->coarse_next);
        memset(&st, 0, sizeof(st));
        tp->get_state(&st);
        mot->tp_done = st.done;
        mot->tp_paused = st.paused;
        mot->tp_probing = st.probing;
        mot->queue_depth = st.queue_depth;
        mot->motion_id = st.exec_id;
        mot->motion_type = st.motion_type;
        mot->current_vel = st.vel;
        mot->distance_to_go = st.dtg;
        mot->par->vel_out = st.vel;
        mot->par->active_tc = st.active_moves > 0 ? st.active_moves
                              : (st.queue_depth > 0 ? 1 : 0);
        mot->tp_spindle_wait = st.waiting;
        line_track(mot, &st);
        r = tp->probe_result(&pr);
        if (r == 1 && !mot->probe_tripped) {
            mot->probe_tripped = 1;
            mot->probed_pos = pr;
        }
        e = tp->take_error();
        if (e && e[0])
            mot_post(mot, "%s", e);
        /* joint coarse positions of the planner's new point */
        for (i = 0; i < KINS_MAX_JOINTS; i++)
            jt[i] = i < mot->num_joints ? mot->joints[i].coarse_pos : 0.0;
        if (mot_inverse(mot, &mot->coarse_next, jt) != 0) {
            mot_post(mot, "coord: inverse kinematics failed at the planned "
                     "position: motion disabled");
            fault(mot);
            return;
        }
        for (i = 0; i < nk; i++) {
            mot_joint_t *j = &mot->joints[i];
            if (HOMED(i)
                && (jt[i] > j->max_pos_limit + 1e-9
                    || jt[i] < j->min_pos_limit - 1e-9)) {
                /* (the end points were checked against the axis limits;
                   this catches joint limits of non-trivial kinematics)
                   stop here, once: a fault */
                mot_post(mot, "coord move would take joint %d past its %s "
                         "soft limit: motion disabled", i,
                         jt[i] > j->max_pos_limit ? "positive" : "negative");
                mot->coarse_next = mot->coarse_prev;
                fault(mot);
                return;
            }
        }
        for (i = 0; i < nk; i++) {
            mot->joints[i].coarse_pos = jt[i];
        }
    }
    mot->traj_count++;
    frac = (double)mot->traj_count / mot->interp_rate;
    if (mot->traj_count >= mot->interp_rate)
        mot->traj_count = 0;
    for (i = 0; i < MOT_MAX_AXES; i++) {
        double a = *emcpose_axis(&mot->coarse_prev, i);
        double b = *emcpose_axis(&mot->coarse_next, i);
        *emcpose_axis(&p, i) = a + (b - a) * frac;
    }
    if (mot->interp_rate == 1) {
        for (i = 0; i < nk; i++)
            jt[i] = mot->joints[i].coarse_pos;
    } else {
        for (i = 0; i < KINS_MAX_JOINTS; i++)
            jt[i] = i < mot->num_joints ? mot->joints[i].pos_cmd : 0.0;
        if (mot_inverse(mot, &p, jt) != 0) {
            mot_post(mot, "coord: inverse kinematics failed: motion disabled");
            fault(mot);
            return;
        }
    }
    mot->carte_pos_cmd = p;
    set_joint_cmds(mot, jt, dt);
}

static void write_pins(mot_t *mot, double dt, long period);

/* feed hold (when enabled: M53), feed inhibit and adaptive feed (when
   enabled: M52) for this cycle */
static void read_feed_inputs(mot_t *mot)
{
    double af = *mot->mp->adaptive_feed;

    mot->feed_hold_now = mot->feed_hold_enabled && *mot->mp->feed_hold;
    mot->feed_inhibit_now = *mot->mp->feed_inhibit ? 1 : 0;
    if (!mot->adaptive_enabled)
        af = 1.0;
    else if (!(af >= 0.0))          /* negative or NaN: stop */
        af = 0.0;
    else if (af > 1.0)
        af = 1.0;
    mot->adaptive_now = af;
}

/* the spindle's commanded speed in rpm (signed), CSS included */
static double spindle_rpm(mot_t *mot, int n)
{
    mot_spindle_t *sp = &mot->spindle[n];
    double rpm = sp->speed, r;

    if (!sp->on)
        return 0.0;
    if (sp->css_factor > 0 && rpm != 0) {
        r = fabs(*emcpose_axis(&mot->carte_pos_cmd, sp->css_axis));
        rpm = sp->css_max > 0 ? sp->css_max : fabs(sp->speed);
        if (r > 1e-9 && sp->css_factor / (2.0 * M_PI * r) < rpm)
            rpm = sp->css_factor / (2.0 * M_PI * r);
        if (sp->speed < 0)
            rpm = -rpm;
    }
    return rpm;
}

/* spindles: amplifier faults, the orient handshake, the output pins */
static void run_spindles(mot_t *mot)
{
    int n;

    for (n = 0; n < mot->num_spindles; n++) {
        mot_spindle_t *sp = &mot->spindle[n];
        mot_spindle_pins_t *p = &mot->sp[n];
        double rpm;

        /* like a joint's amplifier fault: motion cannot stay enabled
           while it is true */
        sp->amp_fault = *p->amp_fault_in ? 1 : 0;
        if (sp->amp_fault && mot->enabled) {
            mot_post(mot, "spindle %d amplifier fault "
                     "(spindle.%d.amp-fault-in): motion disabled", n, n);
            fault(mot);
        }
        if (sp->orient_state == MOT_ORIENT_RUNNING) {
            if (*p->orient_fault != 0) {
                sp->orient_fault = *p->orient_fault;
                sp->orient_state = MOT_ORIENT_FAULT;
                mot_post(mot, "spindle %d orient failed: "
                         "spindle.%d.orient-fault is %d", n, n,
                         sp->orient_fault);
            } else if (*p->is_oriented) {
                sp->orient_state = MOT_ORIENT_DONE;
                sp->brake = 1;
            }
        }
        rpm = spindle_rpm(mot, n);
        if (sp->reversed)
            rpm = -rpm;                 /* rigid tap: coming back out */
        *p->speed_cmd_rps = rpm / 60.0;
        if (*p->inhibit)
            rpm = 0.0;
        *p->on = sp->on && sp->speed != 0;
        *p->forward = *p->on && (sp->speed > 0) != (sp->reversed != 0);
        *p->reverse = *p->on && !*p->forward;
        *p->brake = sp->brake;
        *p->speed_out = rpm;
        *p->speed_out_abs = fabs(rpm);
        *p->speed_out_rps = rpm / 60.0;
        *p->speed_out_rps_abs = fabs(rpm) / 60.0;
        *p->orient = sp->orient_state == MOT_ORIENT_RUNNING;
        *p->locked = sp->orient_state == MOT_ORIENT_DONE;
        *p->orient_angle = sp->orient_angle;
        *p->orient_mode = sp->orient_mode;
        if (sp->index_armed && !*p->index_enable)
            sp->index_armed = 0;        /* the encoder saw the index */
    }
}

void mot_controller(void *arg, long period)
{
    mot_t *mot = arg;
    int i, homing;
    double dt = period > 0 ? period * 1e-9 : mot->servo_period;
    const char *e;
    EmcPose old_carte = mot->carte_pos_cmd;

    mot->heartbeat++;
    read_inputs(mot);
    mot->home->read_inputs();

    /* homing first: in the cycle an encoder resets at the index, homing
       shifts pos_fb and the offset; checking the following error before
       that would see a jump that is not there */
    homing = mot->home->run();
    e = mot->home->take_error();
    if (e && e[0])
        mot_post(mot, "%s", e);
    refresh_home_cache(mot);
    check_faults(mot);
    read_feed_inputs(mot);

    if (!mot->enabled) {
        /* commands follow the feedback */
        for (i = 0; i < mot->num_joints; i++) {
            mot_joint_t *j = &mot->joints[i];
            j->pos_cmd = j->pos_fb;
            j->coarse_pos = j->pos_fb;
            j->vel_cmd = j->acc_cmd = 0.0;
            fp_reset(&j->free_tp, j->pos_cmd);
            mot->jog_kind[i] = MOT_JOG_NONE;
        }
        carte_cmd_from_joints(mot);
        for (i = 0; i < MOT_MAX_AXES; i++) {
            fp_reset(&mot->axis[i].tp, *emcpose_axis(&mot->carte_pos_cmd, i));
            mot->axis[i].jog = MOT_JOG_NONE;
            mot->axis[i].vel_cmd = 0;
        }
        mot->coarse_prev = mot->coarse_next = mot->carte_pos_cmd;
        mot->traj_count = 0;
        if (mot->mode == MOT_MODE_COORD) {
            /* let an aborted planner come to rest (its output is not
               used), then keep it where the machine is, so that ENABLE
               and the next move start from here */
            tp_inputs_t in;
            EmcPose dummy;
            int k;
            memset(&in, 0, sizeof(in));
            if (mot->tp->reset && !mot->tp->is_done())
                mot->tp->reset();
            /* (a planner without reset: run it fast until it is done) */
            for (k = 0; k < 50 && !mot->tp->is_done(); k++)
                mot->tp->run_cycle(&in, &dummy);
            if (mot->tp->is_done())
                mot->tp->set_pos(&mot->carte_pos_cmd, NULL, 0);
            mot->tp_done = 1;
            mot->queue_depth = mot->tp->queue_depth();
        }
    } else if (mot->mode == MOT_MODE_FREE) {
        for (i = 0; i < mot->num_joints; i++)
            run_free_joint(mot, i, dt);
        carte_cmd_from_joints(mot);
        for (i = 0; i < MOT_MAX_AXES; i++) {
            mot->axis[i].vel_cmd = 0;
            fp_reset(&mot->axis[i].tp, *emcpose_axis(&mot->carte_pos_cmd, i));
        }
    } else {
        /* extra joints keep their free planners in every mode */
        for (i = used_kins_joints(mot); i < mot->num_joints; i++)
            if (is_extra(mot, i) || i >= mot->num_joints_used)
                run_free_joint(mot, i, dt);
        if (mot->mode == MOT_MODE_TELEOP)
            run_teleop(mot, dt);
        else
            run_coord(mot, dt);
    }
    (void)homing;

    /* current velocity: speed of the Cartesian command (XYZ, or the
       rotary/other axes for moves without XYZ) */
    {
        double d2 = 0, r2 = 0, d;
        for (i = 0; i < 3; i++) {
            d = *emcpose_axis(&mot->carte_pos_cmd, i)
                - *emcpose_axis(&old_carte, i);
            d2 += d * d;
        }
        for (i = 3; i < MOT_MAX_AXES; i++) {
            d = *emcpose_axis(&mot->carte_pos_cmd, i)
                - *emcpose_axis(&old_carte, i);
            r2 += d * d;
        }
        if (mot->mode != MOT_MODE_COORD || !mot->enabled) {
            mot->current_vel = sqrt(d2 > 0 ? d2 : r2) / dt;
            mot->distance_to_go = 0.0;
        }
    }

    /* outputs: compensation, motor command */
    for (i = 0; i < mot->num_joints; i++) {
        mot_joint_t *j = &mot->joints[i];
        if (posthome_joint(mot, i)) {
            /* posthome-cmd plus the motor offset, feedback ignored */
            j->backlash_corr = j->backlash_filt = j->backlash_vel = 0.0;
            j->motor_pos_cmd = j->pos_cmd + j->motor_offset;
            j->pos_fb = j->pos_cmd;
            j->ferror = 0.0;
            continue;
        }
        mot_comp_joint(mot, i, dt);
        j->motor_pos_cmd = j->pos_cmd + j->backlash_filt + j->motor_offset;
        j->ferror_limit = ferror_limit(j);
    }

    /* carte_pos_fb: forward kinematics of pos_fb; with unhomed joints of
       non-identity kinematics it keeps its last value (we do not know
       where the tool is); without a forward transform it copies
       carte_pos_cmd (the developer manual's proposal) */
    if (mot->kins_type == KINEMATICS_INVERSE_ONLY) {
        mot->carte_fb_ok = 0;
        mot->carte_pos_fb = mot->carte_pos_cmd;
    } else if (kins_valid(mot)) {
        double jt[MOT_MAX_JOINTS];
        EmcPose p;
        for (i = 0; i < mot->num_joints; i++)
            jt[i] = mot->joints[i].pos_fb;
        mot->carte_fb_ok = mot_forward(mot, jt, &p) == 0;
        mot->carte_pos_fb = mot->carte_fb_ok ? p : mot->carte_pos_cmd;
    } else {
        mot->carte_fb_ok = 0;
    }

    run_spindles(mot);
    write_pins(mot, dt, period);
    mot->home->write_outputs();
    mot_write_status(mot);
}

static void write_pins(mot_t *mot, double dt, long period)
{
    int i, inpos = 1, soft = 0, jogging = 0;
    mot_motion_pins_t *mp = mot->mp;

    (void)dt;
    for (i = 0; i < mot->num_joints; i++) {
        mot_joint_t *j = &mot->joints[i];
        mot_joint_pins_t *p = &mot->jp[i];
        int homed = HOMED(i);
        int kb = mot->jog_kind[i] == MOT_JOG_CONT
                 || mot->jog_kind[i] == MOT_JOG_INCR
                 || mot->jog_kind[i] == MOT_JOG_ABS;
        int wh = mot->jog_kind[i] == MOT_JOG_WHEEL;

        j->kb_jog_active = kb;
        j->wheel_jog_active = wh;
        jogging |= kb | wh;
        j->flags &= ~(MOT_JOINT_INPOS | MOT_JOINT_POS_SOFT
                      | MOT_JOINT_NEG_SOFT | MOT_JOINT_HOMED
                      | MOT_JOINT_HOMING | MOT_JOINT_ENABLED);
        if (!j->free_tp.active)
            j->flags |= MOT_JOINT_INPOS;
        else if (i < mot->num_joints_used)
            inpos = 0;
        if (homed) {
            j->flags |= MOT_JOINT_HOMED;
            if (j->pos_cmd >= j->max_pos_limit)
                j->flags |= MOT_JOINT_POS_SOFT;
            if (j->pos_cmd <= j->min_pos_limit)
                j->flags |= MOT_JOINT_NEG_SOFT;
        }
        if (HOMING(i))
            j->flags |= MOT_JOINT_HOMING;
        if ((j->flags & (MOT_JOINT_POS_SOFT | MOT_JOINT_NEG_SOFT))
            && (j->flags & MOT_JOINT_ACTIVE) && i < mot->num_joints_used)
            soft = 1;
        {
            int amp = mot->enabled && (j->flags & MOT_JOINT_ACTIVE);
            if (mot->amp_on[i] > 0)
                amp = 1;
            else if (mot->amp_on[i] < 0)
                amp = 0;
            if (amp)
                j->flags |= MOT_JOINT_ENABLED;
            *p->amp_enable_out = amp;
        }
        if (mot->enabled)
            j->flags &= ~(MOT_JOINT_ERROR | MOT_JOINT_FERROR);

        *p->acc_cmd = j->acc_cmd;
        *p->active = (j->flags & MOT_JOINT_ACTIVE) ? 1 : 0;
        *p->backlash_corr = j->backlash_corr;
        *p->backlash_filt = j->backlash_filt;
        *p->backlash_vel = j->backlash_vel;
        *p->coarse_pos_cmd = j->coarse_pos;
        *p->error = (j->flags & MOT_JOINT_ERROR) ? 1 : 0;
        *p->f_error = j->ferror;
        *p->f_error_lim = j->ferror_limit;
        *p->f_errored = (j->flags & MOT_JOINT_FERROR) ? 1 : 0;
        *p->faulted = (j->flags & MOT_JOINT_FAULT) ? 1 : 0;
        *p->free_pos_cmd = j->free_tp.pos;
        *p->free_tp_enable = j->free_tp.enable ? 1 : 0;
        *p->free_vel_lim = j->free_tp.max_vel;
        *p->in_position = (j->flags & MOT_JOINT_INPOS) ? 1 : 0;
        *p->kb_jog_active = kb;
        *p->motor_offset = j->motor_offset;
        *p->motor_pos_cmd = j->motor_pos_cmd;
        *p->neg_hard_limit = j->neg_limit_sw;
        *p->pos_cmd = j->pos_cmd;
        *p->pos_fb = j->pos_fb;
        *p->pos_hard_limit = j->pos_limit_sw;
        *p->vel_cmd = j->vel_cmd;
        *p->wheel_jog_active = wh;
    }
    for (i = 0; i < MOT_MAX_AXES; i++) {
        mot_axis_t *a = &mot->axis[i];
        mot_axis_pins_t *p = &mot->ap[i];
        int kb = a->jog == MOT_JOG_CONT || a->jog == MOT_JOG_INCR
                 || a->jog == MOT_JOG_ABS;
        int wh = a->jog == MOT_JOG_WHEEL;
        jogging |= kb | wh;
        if (mot->mode == MOT_MODE_TELEOP && a->tp.active)
            inpos = 0;
        *p->pos_cmd = *emcpose_axis(&mot->carte_pos_cmd, i);
        *p->teleop_pos_cmd = a->tp.pos;
        *p->teleop_vel_cmd = a->tp.vel;
        *p->teleop_tp_enable = a->tp.enable ? 1 : 0;
        *p->teleop_vel_lim = a->tp.max_vel;
        *p->kb_jog_active = kb;
        *p->wheel_jog_active = wh;
        *mp->tooloffset[i] = *emcpose_axis(&mot->tool_offset, i);
    }
    if (mot->mode == MOT_MODE_COORD && mot->enabled && !mot->tp_done)
        inpos = 0;
    mot->inpos = inpos;

    *mp->in_position = inpos;
    *mp->motion_enabled = mot->enabled;
    *mp->coord_mode = mot->mode == MOT_MODE_COORD;
    *mp->teleop_mode = mot->mode == MOT_MODE_TELEOP;
    *mp->on_soft_limit = soft;
    *mp->is_all_homed = mot->all_homed_api_c;
    *mp->jog_is_active = jogging;
    *mp->current_vel = mot->current_vel;
    *mp->distance_to_go = mot->distance_to_go;
    *mp->motion_type = mot->mode == MOT_MODE_COORD && !mot->tp_done
                       ? mot->motion_type : 0;
    {
        int running = mot->mode == MOT_MODE_COORD && mot->enabled
                      && !mot->tp_done;
        double upm = 0.0, mm;
        /* the requested velocity of the move that runs (without
           overrides); idle: 0 */
        *mp->requested_vel = running ? mot->move_req_vel : 0.0;
        *mp->program_line = running || mot->tp_paused ? mot->program_line
                                                       : 0;
        /* feed rate of feed moves and arcs: the requested velocity times
           the feed override and adaptive feed, 0 while held; per minute.
           The mm and inch pins need SET_LINEAR_UNITS (else 0) */
        if (running && (mot->motion_type == MOT_MOTION_FEED
                        || mot->motion_type == MOT_MOTION_ARC))
            upm = mot->feed_hold_now || mot->feed_inhibit_now ? 0.0
                  : mot->move_req_vel * mot->feed_scale * mot->adaptive_now
                    * 60.0;
        mot->feed_upm = upm;
        *mp->feed_upm = upm;
        mm = upm * mot->linear_units;
        *mp->feed_mm_per_minute = mm;
        *mp->feed_mm_per_second = mm / 60.0;
        *mp->feed_inches_per_minute = mm / 25.4;
        *mp->feed_inches_per_second = mm / 25.4 / 60.0;
    }
    *mp->servo_last_period = (hal_u32_t)period;
    *mp->coord_error = 0;
    mot->par->pos_out = mot->mode == MOT_MODE_COORD
                        ? mot->tp->distance_to_go() : 0.0;
}

void mot_write_status(mot_t *mot)
{
    mot_channel_t *ch = mot->chan;
    mot_status_t *s;
    uint32_t seq;
    int i;

    if (!ch)
        return;
    s = &ch->status;
    seq = ch->status_seq;
    __atomic_store_n(&ch->status_seq, seq + 1, __ATOMIC_RELAXED);
    __atomic_thread_fence(__ATOMIC_RELEASE);

    s->heartbeat = mot->heartbeat;
    s->mode = mot->mode;
    s->enabled = mot->enabled;
    s->in_position = mot->inpos;
    s->on_soft_limit = *mot->mp->on_soft_limit;
    s->override_limits = mot->override_limits;
    s->num_joints = mot->num_joints_used;
    s->num_joints_loaded = mot->num_joints;
    s->num_extrajoints = mot->num_extra;
    s->kins_type = mot->kins_type;
    s->homing = mot->any_homing_c;
    s->all_homed = mot->all_homed_api_c;
    s->paused = mot->tp_paused;
    s->probing = mot->tp_probing;
    s->probe_tripped = mot->probe_tripped;
    /* a mailbox move held for at-speed counts as queued */
    s->queue_depth = mot->queue_depth + mot->deferred_valid;
    s->motion_id = mot->motion_id;
    s->motion_type = *mot->mp->motion_type;
    s->profile = mot->profile;
    s->coord_error = 0;
    s->error = mot->error;
    s->num_dio = mot->num_dio;
    s->num_aio = mot->num_aio;
    s->num_spindles = mot->num_spindles;
    s->term_cond = mot->term_cond;
    s->feed_scale = mot->feed_scale;
    s->rapid_scale = mot->rapid_scale;
    s->current_vel = mot->current_vel;
    s->distance_to_go = mot->distance_to_go;
    s->requested_vel = mot->req_vel;
    s->vel_limit = mot->vel_limit;
    s->acc_limit = mot->acc_limit;
    s->tolerance = mot->tolerance;
    s->servo_period = mot->servo_period;
    s->traj_period = mot->traj_period;
    s->carte_pos_cmd = mot->carte_pos_cmd;
    s->carte_pos_fb = mot->carte_pos_fb;
    s->carte_pos_fb_ok = mot->carte_fb_ok;
    s->probed_pos = mot->probed_pos;
    s->tool_offset = mot->tool_offset;
    s->dout = 0;
    s->din = 0;
    for (i = 0; i < mot->num_dio; i++) {
        if (*mot->mp->digital_out[i])
            s->dout |= 1ull << i;
        if (*mot->mp->digital_in[i])
            s->din |= 1ull << i;
    }
    s->program_line = *mot->mp->program_line;
    s->feed_hold_enabled = mot->feed_hold_enabled;
    s->adaptive_enabled = mot->adaptive_enabled;
    s->feed_hold = mot->feed_hold_now;
    s->feed_inhibit = mot->feed_inhibit_now;
    s->queue_taken = (int32_t)ch->q_tail;
    s->queue_err_count = __atomic_load_n(&ch->q_err_count, __ATOMIC_RELAXED);
    s->adaptive_feed = *mot->mp->adaptive_feed;
    s->feed_upm = mot->feed_upm;
    s->linear_units = mot->linear_units;
    s->spindle_wait = mot->tp_spindle_wait;
    s->queue_held = mot->wait_at_speed;
    for (i = 0; i < mot->num_aio; i++) {
        s->ain[i] = *mot->mp->analog_in[i];
        s->aout[i] = *mot->mp->analog_out[i];
    }
    for (i = 0; i < mot->num_spindles; i++) {
        mot_spindle_t *sp = &mot->spindle[i];
        mot_spindle_pins_t *p = &mot->sp[i];
        mot_spindle_status_t *ss = &s->spindle[i];
        ss->speed = *p->speed_out;
        ss->speed_in = *p->speed_in;
        ss->revs = *p->revs;
        ss->orient_angle = sp->orient_angle;
        ss->css_factor = sp->css_factor;
        ss->on = *p->on;
        ss->direction = *p->forward ? 1 : (*p->reverse ? -1 : 0);
        ss->brake = *p->brake;
        ss->locked = *p->locked;
        ss->orient_state = sp->orient_state;
        ss->orient_fault = sp->orient_fault;
        ss->at_speed = *p->at_speed;
        ss->inhibit = *p->inhibit;
        ss->amp_fault = *p->amp_fault_in;
    }
    for (i = 0; i < mot->num_joints; i++) {
        mot_joint_t *j = &mot->joints[i];
        mot_joint_status_t *js = &s->joint[i];
        js->flags = j->flags;
        js->home_state = mot->home->state(i);
        js->pos_cmd = j->pos_cmd;
        js->pos_fb = j->pos_fb;
        js->vel_cmd = j->vel_cmd;
        js->acc_cmd = j->acc_cmd;
        js->ferror = j->ferror;
        js->ferror_limit = j->ferror_limit;
        js->ferror_high_mark = j->ferror_high_mark;
        js->motor_offset = j->motor_offset;
        js->motor_pos_cmd = j->motor_pos_cmd;
        js->motor_pos_fb = j->motor_pos_fb;
        js->backlash_filt = j->backlash_filt;
        js->min_pos_limit = j->min_pos_limit;
        js->max_pos_limit = j->max_pos_limit;
        js->vel_limit = j->vel_limit;
        js->acc_limit = j->acc_limit;
        js->jerk_limit = j->jerk_limit;
        js->min_ferror = j->min_ferror;
        js->max_ferror = j->max_ferror;
        js->backlash = j->backlash;
        js->free_target = j->free_tp.target;
        js->free_active = j->free_tp.active;
        js->jog_active = mot->jog_kind[i] != MOT_JOG_NONE;
    }
    for (i = 0; i < MOT_MAX_AXES; i++) {
        mot_axis_t *a = &mot->axis[i];
        mot_axis_status_t *as = &s->axis[i];
        as->pos_cmd = *emcpose_axis(&mot->carte_pos_cmd, i);
        as->vel_cmd = a->vel_cmd;
        as->teleop_pos = a->tp.pos;
        as->teleop_vel = a->tp.vel;
        as->teleop_target = a->tp.target;
        as->min_pos_limit = a->min_pos_limit;
        as->max_pos_limit = a->max_pos_limit;
        as->vel_limit = a->vel_limit;
        as->acc_limit = a->acc_limit;
        as->jerk_limit = a->jerk_limit;
        as->teleop_active = a->tp.active;
        as->jog_active = a->jog != MOT_JOG_NONE;
    }

    __atomic_thread_fence(__ATOMIC_RELEASE);
    __atomic_store_n(&ch->status_seq, seq + 2, __ATOMIC_RELEASE);
}
