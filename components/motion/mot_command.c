/*
 * mot_command.c - motion-command-handler, the function of motmod that
 * takes commands from the channel (channel.h describes the protocol).
 *
 * Once per servo cycle: if the client published a new sequence number,
 * copy the command, check it and either carry it out or refuse it with
 * a reason, then echo.  Where the developer manual says a command is
 * "ignored silently" when it cannot run, we refuse it with the reason
 * instead.  Decisions of ours (documented here, since the manual leaves
 * them open):
 *  - mode changes (FREE/TELEOP/COORD) are refused while anything moves
 *    or a joint homes; TELEOP and COORD need all joints homed unless the
 *    kinematics are identity;
 *  - jogs of different joints (or axes) may run at the same time; a jog
 *    is refused when motion is disabled, in the wrong mode, while a
 *    joint homes, while motion.jog-inhibit is true, and when the joint
 *    is at (or beyond) a soft limit and the jog would go further;
 *  - a joint jog (joint >= 0) needs free mode, an axis jog (joint = -1,
 *    axis >= 0) teleop mode;
 *  - joints with a negative HOME_SEQUENCE (synchronized homing, e.g. the
 *    two sides of a gantry) cannot be jogged alone (joint jogs refused);
 *  - JOG_INCR adds to the target of a JOG_INCR still running on the same
 *    joint (incremental jogs are cumulative), else to the position now;
 *  - jog velocities above the joint's (axis') limit are reduced to it;
 *  - HOME is refused unless in free mode, enabled, motion.homing-inhibit
 *    false and the joint (all joints for -1) at rest;
 *  - OVERRIDE_LIMITS (ival 1) lets hard limits pass until the end of the
 *    next jog (the jog that starts after it, when it stops); ival 0
 *    cancels it;
 *  - PAUSE, RESUME and STEP go to the trajectory planner in any mode
 *    (they act in coord mode);
 *  - velocity/acceleration arguments of SET_LINE, SET_CIRCLE and PROBE:
 *    ini_maxvel 0 means the SET_VEL_LIMIT value, acc 0 the SET_ACC value
 *    (both must then have been set);
 *  - the configuration commands may be sent at any time, except
 *    SET_NUM_JOINTS (needs motion disabled);
 *  - after the mailbox, the move queue of the channel is drained into
 *    the planner (channel.h "The move queue"): up to MOT_QUEUE_BURST
 *    records a cycle while the planner has room; the first refused record
 *    stops the queue and drops the records written after it;
 *  - a spindle start or speed change makes the next feed move wait until
 *    the planner has run out and the turning spindles are at speed (the
 *    queue, or the mailbox, holds it); SPINDLE_OFF of the last turning
 *    spindle cancels the wait;
 *  - SPINDLE_ON and SPINDLE_ORIENT need motion enabled; DISABLE and
 *    faults stop the spindles; the brake is engaged by SPINDLE_OFF, by a
 *    finished orient and by BRAKE_ENGAGE (refused while turning).
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

static char *why;               /* the echo's reason text */
static int whylen;

static const char *const mode_names[] = { "free", "teleop", "coord" };
static const char axis_letters[] = "XYZABCUVW";

static int reject(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int reject(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, whylen, fmt, ap);
    va_end(ap);
    return MOT_ECHO_REJECTED;
}

static const char *cmd_name(int c)
{
    switch (c) {
    case MOT_CMD_JOG_CONT: return "JOG_CONT";
    case MOT_CMD_JOG_INCR: return "JOG_INCR";
    case MOT_CMD_JOG_ABS: return "JOG_ABS";
    case MOT_CMD_JOG_STOP: return "JOG_STOP";
    case MOT_CMD_SET_LINE: return "SET_LINE";
    case MOT_CMD_SET_CIRCLE: return "SET_CIRCLE";
    case MOT_CMD_PROBE: return "PROBE";
    case MOT_CMD_SET_TELEOP_VECTOR: return "SET_TELEOP_VECTOR";
    case MOT_CMD_HOME: return "HOME";
    case MOT_CMD_UNHOME: return "UNHOME";
    case MOT_CMD_TELEOP: return "TELEOP";
    case MOT_CMD_COORD: return "COORD";
    case MOT_CMD_FREE: return "FREE";
    case MOT_CMD_SET_DOUT: return "SET_DOUT";
    case MOT_CMD_SET_AOUT: return "SET_AOUT";
    case MOT_CMD_SET_TERM_COND: return "SET_TERM_COND";
    case MOT_CMD_SET_VEL: return "SET_VEL";
    case MOT_CMD_SET_ACC: return "SET_ACC";
    case MOT_CMD_SET_VEL_LIMIT: return "SET_VEL_LIMIT";
    case MOT_CMD_SET_FEED_HOLD_ENABLE: return "SET_FEED_HOLD_ENABLE";
    case MOT_CMD_SET_ADAPTIVE_FEED_ENABLE: return "SET_ADAPTIVE_FEED_ENABLE";
    case MOT_CMD_SET_LINEAR_UNITS: return "SET_LINEAR_UNITS";
    case MOT_CMD_SPINDLE_ON: return "SPINDLE_ON";
    case MOT_CMD_SPINDLE_OFF: return "SPINDLE_OFF";
    case MOT_CMD_SPINDLE_INCREASE: return "SPINDLE_INCREASE";
    case MOT_CMD_SPINDLE_DECREASE: return "SPINDLE_DECREASE";
    case MOT_CMD_SPINDLE_ORIENT: return "SPINDLE_ORIENT";
    case MOT_CMD_SPINDLE_BRAKE_ENGAGE: return "SPINDLE_BRAKE_ENGAGE";
    case MOT_CMD_SPINDLE_BRAKE_RELEASE: return "SPINDLE_BRAKE_RELEASE";
    case MOT_CMD_SPINDLE_SYNC_LINE: return "SPINDLE_SYNC_LINE";
    case MOT_CMD_RIGID_TAP: return "RIGID_TAP";
    default: return "the command";
    }
}

/* ---- argument checks: each returns 0 or the rejection ---- */
static int bad_joint(int j)
{
    if (j < 0 || j >= mot->num_joints_used)
        return reject("joint %d does not exist (num_joints=%d)", j,
                      mot->num_joints_used);
    return 0;
}

static int bad_axis(int a)
{
    if (a < 0 || a >= MOT_MAX_AXES)
        return reject("axis %d does not exist (axes are 0..8 for X..W)", a);
    return 0;
}

static int bad_pos(const char *what, double v)
{
    if (!isfinite(v))
        return reject("%s must be a finite number, got %g", what, v);
    return 0;
}

static int bad_positive(const char *what, double v)
{
    if (!isfinite(v) || v <= 0)
        return reject("%s must be a positive number, got %g", what, v);
    return 0;
}

static int bad_nonneg(const char *what, double v)
{
    if (!isfinite(v) || v < 0)
        return reject("%s must be zero or a positive number, got %g", what,
                      v);
    return 0;
}

static int bad_pose(const char *what, const EmcPose *p)
{
    int i;
    for (i = 0; i < MOT_MAX_AXES; i++) {
        double v = *emcpose_axis((EmcPose *)p, i);
        if (!isfinite(v))
            return reject("%s %c must be a finite number, got %g", what,
                          axis_letters[i], v);
    }
    return 0;
}

static int bad_cart(const char *what, const PmCartesian *c)
{
    if (!isfinite(c->x) || !isfinite(c->y) || !isfinite(c->z))
        return reject("%s must be finite numbers, got (%g, %g, %g)", what,
                      c->x, c->y, c->z);
    return 0;
}

static int any_homing(void)
{
    int i;
    for (i = 0; i < mot->num_joints; i++)
        if (mot->home->is_homing(i))
            return 1;
    return 0;
}

static int first_moving(void)
{
    int i;
    for (i = 0; i < mot->num_joints_used; i++)
        if (mot->joints[i].free_tp.active)
            return i;
    return -1;
}

/* ---- modes ---- */
static int cmd_mode(const mot_command_t *c)
{
    int want = c->cmd == MOT_CMD_FREE ? MOT_MODE_FREE
               : c->cmd == MOT_CMD_TELEOP ? MOT_MODE_TELEOP : MOT_MODE_COORD;
    int j;

    if (mot->mode == want)
        return MOT_ECHO_DONE;
    if (any_homing())
        return reject("%s: cannot change mode while a joint is homing",
                      cmd_name(c->cmd));
    if (mot_moving()) {
        j = first_moving();
        if (j >= 0)
            return reject("%s: cannot change mode while joint %d moves "
                          "(now %s)", cmd_name(c->cmd), j,
                          mode_names[mot->mode]);
        return reject("%s: cannot change mode while the machine moves "
                      "(now %s)", cmd_name(c->cmd), mode_names[mot->mode]);
    }
    if (want != MOT_MODE_FREE) {
        if (mot->kins_type != KINEMATICS_IDENTITY && !mot_all_homed())
            return reject("%s needs all joints homed (the kinematics are "
                          "not identity)", cmd_name(c->cmd));
        if (mot->kins_type == KINEMATICS_FORWARD_ONLY)
            return reject("%s needs inverse kinematics (the kinematics "
                          "module has forward only)", cmd_name(c->cmd));
    }
    mot_sync_planners();
    if (want == MOT_MODE_COORD) {
        char w[MOT_REASON_LEN];
        w[0] = 0;
        if (mot->tp->set_pos(&mot->carte_pos_cmd, w, sizeof(w)) < 0)
            return reject("COORD: the trajectory planner refused the "
                          "present position: %s", w);
        mot->tp_done = 1;
        mot->queue_depth = 0;
    }
    mot->mode = want;
    return MOT_ECHO_DONE;
}

/* ---- jogs ---- */
static double jog_speed(double v, double lim)
{
    v = fabs(v) * mot->feed_scale;
    return v > lim ? lim : v;
}

/* the jog starts: remember it for OVERRIDE_LIMITS */
static void jog_started(int who)
{
    if (mot->override_limits && mot->override_jog < 0)
        mot->override_jog = who;
}

static int cmd_jog_joint(const mot_command_t *c)
{
    const char *name = cmd_name(c->cmd);
    int n = c->joint, homed, r;
    mot_joint_t *j;
    double t, spd, dir;

    if (mot->mode != MOT_MODE_FREE)
        return reject("%s of a joint needs free mode (now %s)", name,
                      mode_names[mot->mode]);
    if ((r = bad_joint(n)))
        return r;
    j = &mot->joints[n];
    if (c->cmd == MOT_CMD_JOG_STOP) {
        j->free_tp.enable = 0;
        return MOT_ECHO_DONE;
    }
    if (!mot->enabled)
        return reject("%s needs motion enabled", name);
    if (any_homing())
        return reject("%s: cannot jog while a joint is homing", name);
    if (*mot->mp->jog_inhibit)
        return reject("%s: jogging is inhibited (motion.jog-inhibit is "
                      "true)", name);
    if (!(j->flags & MOT_JOINT_ACTIVE))
        return reject("%s: joint %d is not active", name, n);
    if (mot->home_seq[n] < 0 && mot->home_seq[n] != HOME_SEQUENCE_NONE)
        return reject("%s: joint %d homes in a synchronized sequence "
                      "(HOME_SEQUENCE %d) and cannot be jogged alone",
                      name, n, mot->home_seq[n]);
    homed = mot->home->is_homed(n);

    if (c->cmd == MOT_CMD_JOG_CONT) {
        if (!isfinite(c->vel) || c->vel == 0)
            return reject("velocity must be a nonzero number, got %g",
                          c->vel);
        dir = c->vel > 0 ? 1 : -1;
        t = homed ? (dir > 0 ? j->max_pos_limit : j->min_pos_limit)
                  : j->pos_cmd + dir * MOT_FAR;
    } else {
        if ((r = bad_positive("velocity", c->vel)))
            return r;
        if (c->cmd == MOT_CMD_JOG_INCR) {
            if ((r = bad_pos("increment", c->offset)))
                return r;
            t = (mot->jog_kind[n] == MOT_JOG_INCR && j->free_tp.enable)
                ? j->free_tp.target : j->pos_cmd;
            t += c->offset;
        } else {
            if ((r = bad_pos("position", c->offset)))
                return r;
            t = c->offset;
        }
        dir = t > j->pos_cmd ? 1 : (t < j->pos_cmd ? -1 : 0);
    }
    if (homed) {
        if (dir > 0 && j->pos_cmd >= j->max_pos_limit)
            return reject("%s: joint %d is at its positive soft limit "
                          "(%g)", name, n, j->max_pos_limit);
        if (dir < 0 && j->pos_cmd <= j->min_pos_limit)
            return reject("%s: joint %d is at its negative soft limit "
                          "(%g)", name, n, j->min_pos_limit);
        if (t > j->max_pos_limit)
            t = j->max_pos_limit;
        if (t < j->min_pos_limit)
            t = j->min_pos_limit;
    }
    /* a limit switch already hit (while limits are overridden): only
       away from it */
    if (dir > 0 && j->pos_limit_sw)
        return reject("%s: joint %d is on its positive hard limit switch",
                      name, n);
    if (dir < 0 && j->neg_limit_sw)
        return reject("%s: joint %d is on its negative hard limit switch",
                      name, n);
    spd = jog_speed(c->vel, j->vel_limit);
    if (!(spd > 0))
        return reject("%s: the jog speed is 0 (feed scale %g)", name,
                      mot->feed_scale);
    mot_joint_limits_to_planner(n);
    j->free_tp.max_vel = spd;
    j->free_tp.target = t;
    j->free_tp.enable = 1;
    mot->jog_kind[n] = c->cmd == MOT_CMD_JOG_CONT ? MOT_JOG_CONT
                       : c->cmd == MOT_CMD_JOG_INCR ? MOT_JOG_INCR
                       : MOT_JOG_ABS;
    mot->jog_vel[n] = spd;
    jog_started(n);
    return MOT_ECHO_ACCEPTED;
}

static double axis_clamp(int n, double t, int *limited)
{
    mot_axis_t *a = &mot->axis[n];
    *limited = 0;
    if (!mot_all_homed())
        return t;
    if (t > a->max_pos_limit) {
        t = a->max_pos_limit;
        *limited = 1;
    }
    if (t < a->min_pos_limit) {
        t = a->min_pos_limit;
        *limited = 1;
    }
    return t;
}

static int cmd_jog_axis(const mot_command_t *c)
{
    const char *name = cmd_name(c->cmd);
    int n = c->axis, r, lim;
    mot_axis_t *a;
    double t, spd, dir, pos;

    if (mot->mode != MOT_MODE_TELEOP)
        return reject("%s of an axis needs teleop mode (now %s)", name,
                      mode_names[mot->mode]);
    if ((r = bad_axis(n)))
        return r;
    a = &mot->axis[n];
    if (c->cmd == MOT_CMD_JOG_STOP) {
        a->tp.enable = 0;
        return MOT_ECHO_DONE;
    }
    if (!mot->enabled)
        return reject("%s needs motion enabled", name);
    if (*mot->mp->jog_inhibit)
        return reject("%s: jogging is inhibited (motion.jog-inhibit is "
                      "true)", name);
    pos = a->tp.pos;
    if (c->cmd == MOT_CMD_JOG_CONT) {
        if (!isfinite(c->vel) || c->vel == 0)
            return reject("velocity must be a nonzero number, got %g",
                          c->vel);
        dir = c->vel > 0 ? 1 : -1;
        t = pos + dir * MOT_FAR;
    } else {
        if ((r = bad_positive("velocity", c->vel)))
            return r;
        if (c->cmd == MOT_CMD_JOG_INCR) {
            if ((r = bad_pos("increment", c->offset)))
                return r;
            t = (a->jog == MOT_JOG_INCR && a->tp.enable) ? a->tp.target
                                                          : pos;
            t += c->offset;
        } else {
            if ((r = bad_pos("position", c->offset)))
                return r;
            t = c->offset;
        }
        dir = t > pos ? 1 : (t < pos ? -1 : 0);
    }
    t = axis_clamp(n, t, &lim);
    if (mot_all_homed()) {
        if (dir > 0 && pos >= a->max_pos_limit)
            return reject("%s: axis %c is at its positive limit (%g)",
                          name, axis_letters[n], a->max_pos_limit);
        if (dir < 0 && pos <= a->min_pos_limit)
            return reject("%s: axis %c is at its negative limit (%g)",
                          name, axis_letters[n], a->min_pos_limit);
    }
    spd = jog_speed(c->vel, a->vel_limit);
    if (!(spd > 0))
        return reject("%s: the jog speed is 0 (feed scale %g)", name,
                      mot->feed_scale);
    mot_axis_limits_to_planner(n);
    a->tp.max_vel = spd;
    a->tp.target = t;
    a->tp.enable = 1;
    a->jog = c->cmd == MOT_CMD_JOG_CONT ? MOT_JOG_CONT
             : c->cmd == MOT_CMD_JOG_INCR ? MOT_JOG_INCR : MOT_JOG_ABS;
    a->req_vel = spd;
    jog_started(100 + n);
    return MOT_ECHO_ACCEPTED;
}

static int cmd_jog(const mot_command_t *c)
{
    if (c->joint >= 0)
        return cmd_jog_joint(c);
    if (c->joint == -1 && c->axis >= 0)
        return cmd_jog_axis(c);
    if (c->joint < -1)
        return reject("joint %d does not exist (num_joints=%d)", c->joint,
                      mot->num_joints_used);
    return reject("%s needs a joint (free mode) or an axis with joint "
                  "-1 (teleop mode)", cmd_name(c->cmd));
}

/* ---- spindles ---- */
static int bad_spindle(int n)
{
    if (n < 0 || n >= mot->num_spindles)
        return reject("spindle %d does not exist (num_spindles=%d)", n,
                      mot->num_spindles);
    return 0;
}

/* ---- coordinated moves ---- */
/* min_limit and max_limit of a SET_*_POSITION_LIMITS command */
static int bad_limits(const mot_command_t *c)
{
    int r;

    if ((r = bad_pos("min_limit", c->min_limit))
        || (r = bad_pos("max_limit", c->max_limit)))
        return r;
    if (c->min_limit > c->max_limit)
        return reject("min_limit (%g) must not be above max_limit (%g)",
                      c->min_limit, c->max_limit);
    return 0;
}

static int move_args(const mot_command_t *c, tp_move_t *m)
{
    int r;
    const char *name = cmd_name(c->cmd);

    if (mot->mode != MOT_MODE_COORD)
        return reject("%s needs coord mode (now %s)", name,
                      mode_names[mot->mode]);
    if (!mot->enabled)
        return reject("%s needs motion enabled", name);
    if ((r = bad_pose("end point", &c->pos)))
        return r;
    if ((r = bad_positive("velocity", c->vel)))
        return r;
    memset(m, 0, sizeof(*m));
    m->id = c->id;
    m->type = c->motion_type;
    m->vel = c->vel;
    m->ini_maxvel = c->ini_maxvel;
    m->acc = c->acc;
    m->jerk = c->jerk;
    m->term_cond = mot->term_cond;
    m->tolerance = mot->tolerance;
    m->cam_tolerance = mot->cam_tolerance;
    m->flags = (unsigned)c->ival;
    if (c->cmd == MOT_CMD_PROBE)
        m->flags = 0;
    if (c->cmd == MOT_CMD_SPINDLE_SYNC_LINE || c->cmd == MOT_CMD_RIGID_TAP) {
        int n = c->index;
        if ((r = bad_spindle(n)))
            return r;
        if ((r = bad_positive("pitch", c->pitch)))
            return r;
        if (!mot->spindle[n].on || mot->spindle[n].speed == 0)
            return reject("%s needs spindle %d turning (SPINDLE_ON first)",
                          name, n);
        m->sync = TP_SYNC_POSITION;
        m->spindle = n;
        m->pitch = c->pitch;
    }
    if (m->ini_maxvel == 0)
        m->ini_maxvel = mot->vel_limit;
    if (m->acc == 0)
        m->acc = mot->acc_limit;
    if ((r = bad_positive("maximum velocity (ini_maxvel, or SET_VEL_LIMIT "
                          "when 0)", m->ini_maxvel)))
        return r;
    if ((r = bad_positive("acceleration (acc, or SET_ACC when 0)", m->acc)))
        return r;
    if ((r = bad_nonneg("jerk", m->jerk)))
        return r;
    if (c->motion_type < 0 || c->motion_type > MOT_MOTION_INDEXROTARY)
        return reject("motion type %d is not one of 0..6", c->motion_type);
    /* the end point must be inside the axes' limits (when they apply) */
    if (mot->all_homed_c) {
        int i;
        for (i = 0; i < MOT_MAX_AXES; i++) {
            mot_axis_t *a = &mot->axis[i];
            double v = *emcpose_axis((EmcPose *)&c->pos, i);
            if (v > a->max_pos_limit || v < a->min_pos_limit)
                return reject("%s: the end point %c=%g is outside the axis "
                              "limits %g..%g", name, axis_letters[i], v,
                              a->min_pos_limit, a->max_pos_limit);
        }
    }
    return 0;
}

/* all checks of a move command before it goes to the planner */
static int check_move(const mot_command_t *c, tp_move_t *m)
{
    int r;

    if ((r = move_args(c, m)))
        return r;
    if (c->cmd == MOT_CMD_SET_CIRCLE) {
        if ((r = bad_cart("center", &c->center)))
            return r;
        if ((r = bad_cart("normal", &c->normal)))
            return r;
        if (c->normal.x == 0 && c->normal.y == 0 && c->normal.z == 0)
            return reject("SET_CIRCLE: the normal must not be (0, 0, 0)");
    } else if (c->cmd == MOT_CMD_PROBE && mot->probe_tripped) {
        return reject("PROBE: the probe flag is still set (send "
                      "CLEAR_PROBE_FLAG first)");
    } else if (c->cmd == MOT_CMD_RIGID_TAP && !mot->tp->add_rigid_tap) {
        return reject("RIGID_TAP: the trajectory planner cannot do "
                      "rigid tapping");
    }
    return 0;
}

static int cmd_move(const mot_command_t *c)
{
    tp_move_t m;
    char w[MOT_REASON_LEN];
    int r;

    if ((r = check_move(c, &m)))
        return r;
    w[0] = 0;
    if (c->cmd == MOT_CMD_SET_LINE || c->cmd == MOT_CMD_SPINDLE_SYNC_LINE)
        r = mot->tp->add_line(&c->pos, &m, w, sizeof(w));
    else if (c->cmd == MOT_CMD_SET_CIRCLE)
        r = mot->tp->add_circle(&c->pos, &c->center, &c->normal, c->turn,
                                &m, w, sizeof(w));
    else if (c->cmd == MOT_CMD_PROBE)
        r = mot->tp->add_probe(&c->pos, &m, c->ival, w, sizeof(w));
    else
        r = mot->tp->add_rigid_tap(&c->pos, &m, w, sizeof(w));
    if (r < 0)
        return reject("%s: %s", cmd_name(c->cmd),
                      w[0] ? w : "the trajectory planner refused it");
    mot->tp_done = 0;
    mot_line_push(c->id, c->line, c->vel);
    return MOT_ECHO_ACCEPTED;
}

static int cmd_teleop_vector(const mot_command_t *c)
{
    int i, r, lim;

    if (mot->mode != MOT_MODE_TELEOP)
        return reject("SET_TELEOP_VECTOR needs teleop mode (now %s)",
                      mode_names[mot->mode]);
    if (!mot->enabled)
        return reject("SET_TELEOP_VECTOR needs motion enabled");
    if ((r = bad_pose("velocity of axis", &c->pos)))
        return r;
    for (i = 0; i < MOT_MAX_AXES; i++) {
        mot_axis_t *a = &mot->axis[i];
        double v = *emcpose_axis((EmcPose *)&c->pos, i);
        if (v == 0) {
            a->tp.enable = 0;
            continue;
        }
        mot_axis_limits_to_planner(i);
        a->tp.max_vel = jog_speed(v, a->vel_limit);
        a->tp.target = axis_clamp(i, a->tp.pos + (v > 0 ? MOT_FAR : -MOT_FAR),
                                  &lim);
        a->tp.enable = 1;
        a->jog = MOT_JOG_NONE;
    }
    return MOT_ECHO_ACCEPTED;
}

/* ---- homing ---- */
static int cmd_home(const mot_command_t *c)
{
    int r, i;
    char w[MOT_REASON_LEN];

    if (mot->mode != MOT_MODE_FREE)
        return reject("HOME needs free mode (now %s)", mode_names[mot->mode]);
    if (!mot->enabled)
        return reject("HOME needs motion enabled");
    if (*mot->mp->homing_inhibit)
        return reject("HOME: homing is inhibited (motion.homing-inhibit is "
                      "true)");
    if (c->joint != -1 && (r = bad_joint(c->joint)))
        return r;
    for (i = 0; i < mot->num_joints_used; i++) {
        if ((c->joint == -1 || c->joint == i)
            && mot->joints[i].free_tp.active && !mot->home->is_homing(i))
            return reject("HOME: joint %d is moving (wait until it stops)",
                          i);
    }
    w[0] = 0;
    r = mot->home->start(c->joint, w, sizeof(w));
    if (r < 0)
        return reject("HOME: %s", w[0] ? w : "the homing module refused");
    return MOT_ECHO_ACCEPTED;
}

static int cmd_unhome(const mot_command_t *c)
{
    int r;
    char w[MOT_REASON_LEN];

    if (c->joint < -2)
        return reject("UNHOME: joint %d is neither a joint nor -1 (all) or "
                      "-2 (volatile ones)", c->joint);
    if (c->joint >= 0 && (r = bad_joint(c->joint)))
        return r;
    if (mot->mode != MOT_MODE_FREE && c->joint != -2)
        return reject("UNHOME needs free mode (now %s)",
                      mode_names[mot->mode]);
    /* motion(9): extra joints may be unhomed only while disabled (-2,
       the volatile ones, is left to the homing module) */
    if (mot->enabled && mot->num_extra > 0 && c->joint != -2) {
        int i;
        for (i = mot->num_joints - mot->num_extra; i < mot->num_joints;
             i++)
            if ((c->joint == i || c->joint == -1) && mot->home->is_homed(i))
                return reject("UNHOME: extra joint %d can be unhomed only "
                              "while motion is disabled", i);
    }
    w[0] = 0;
    r = mot->home->unhome(c->joint, w, sizeof(w));
    if (r < 0)
        return reject("UNHOME: %s", w[0] ? w : "the homing module refused");
    return MOT_ECHO_DONE;
}

static int any_spindle_on(void)
{
    int i;
    for (i = 0; i < mot->num_spindles; i++)
        if (mot->spindle[i].on && mot->spindle[i].speed != 0)
            return 1;
    return 0;
}

/* a new speed or direction: the next feed move waits for at-speed */
static void spindle_changed(mot_spindle_t *sp, double old)
{
    if (sp->speed != old)
        mot->wait_at_speed = 1;
}

static int cmd_spindle(const mot_command_t *c)
{
    const char *name = cmd_name(c->cmd);
    mot_spindle_t *sp;
    int r, n = c->index;
    double old, step;

    if ((r = bad_spindle(n)))
        return r;
    sp = &mot->spindle[n];
    old = sp->on ? sp->speed : 0.0;
    switch (c->cmd) {
    case MOT_CMD_SPINDLE_ON:
        if (!mot->enabled)
            return reject("SPINDLE_ON needs motion enabled");
        if ((r = bad_pos("spindle speed", c->vel)))
            return r;
        if (c->value != 0) {
            if ((r = bad_positive("CSS surface speed", c->value))
                || (r = bad_nonneg("CSS maximum speed", c->offset)))
                return r;
            if (c->ival < 0 || c->ival >= MOT_MAX_AXES)
                return reject("SPINDLE_ON: CSS axis %d does not exist (axes "
                              "are 0..8 for X..W)", c->ival);
        }
        if (*mot->sp[n].amp_fault_in)
            return reject("SPINDLE_ON: spindle %d has an amplifier fault "
                          "(spindle.%d.amp-fault-in is true)", n, n);
        sp->speed = c->vel;
        sp->css_factor = c->value;
        sp->css_axis = c->ival;
        sp->css_max = c->offset;
        sp->on = 1;
        sp->brake = 0;
        sp->orient_state = MOT_ORIENT_NONE;
        sp->amp_fault = 0;
        spindle_changed(sp, old);
        if (!old)
            mot->wait_at_speed = 1;
        return MOT_ECHO_DONE;

    case MOT_CMD_SPINDLE_OFF:
        sp->speed = 0.0;
        sp->css_factor = 0.0;
        sp->on = 0;
        sp->brake = 1;
        sp->orient_state = MOT_ORIENT_NONE;
        if (!any_spindle_on())
            mot->wait_at_speed = 0;     /* nothing left to wait for */
        return MOT_ECHO_DONE;

    case MOT_CMD_SPINDLE_INCREASE:
    case MOT_CMD_SPINDLE_DECREASE:
        if ((r = bad_nonneg("speed step", c->value)))
            return r;
        if (!sp->on || sp->speed == 0)
            return reject("%s: spindle %d is off", name, n);
        step = c->value > 0 ? c->value : 0.1 * fabs(sp->speed);
        if (c->cmd == MOT_CMD_SPINDLE_DECREASE) {
            if (step >= fabs(sp->speed))
                return reject("SPINDLE_DECREASE: a step of %g rpm would "
                              "stop spindle %d (now %g rpm); use "
                              "SPINDLE_OFF", step, n, sp->speed);
            step = -step;
        }
        sp->speed += sp->speed > 0 ? step : -step;
        spindle_changed(sp, old);
        return MOT_ECHO_DONE;

    case MOT_CMD_SPINDLE_ORIENT:
        if (!mot->enabled)
            return reject("SPINDLE_ORIENT needs motion enabled");
        if ((r = bad_pos("orient angle", c->value)))
            return r;
        sp->speed = 0.0;
        sp->css_factor = 0.0;
        sp->on = 0;
        sp->brake = 0;
        sp->orient_angle = c->value;
        sp->orient_mode = c->ival;
        sp->orient_fault = 0;
        sp->orient_state = MOT_ORIENT_RUNNING;
        return MOT_ECHO_ACCEPTED;

    case MOT_CMD_SPINDLE_BRAKE_ENGAGE:
        if (sp->on && sp->speed != 0)
            return reject("SPINDLE_BRAKE_ENGAGE: spindle %d turns (%g rpm); "
                          "send SPINDLE_OFF first", n, sp->speed);
        sp->brake = 1;
        return MOT_ECHO_DONE;

    case MOT_CMD_SPINDLE_BRAKE_RELEASE:
        sp->brake = 0;
        return MOT_ECHO_DONE;
    }
    return reject("%s is not a spindle command", name);
}

void mot_spindles_stop(void)
{
    int i;
    mot->wait_at_speed = 0;
    for (i = 0; i < mot->num_spindles; i++) {
        mot_spindle_t *sp = &mot->spindle[i];
        if (sp->on) {
            sp->brake = 1;
        }
        sp->speed = 0.0;
        sp->css_factor = 0.0;
        sp->on = 0;
        if (sp->orient_state == MOT_ORIENT_RUNNING)
            sp->orient_state = MOT_ORIENT_NONE;
        if (sp->index_armed) {
            *mot->sp[i].index_enable = 0;
            sp->index_armed = 0;
        }
    }
}

/* ---- the dispatcher ---- */
static int run_command(const mot_command_t *c)
{
    int r, i;
    mot_joint_t *j;
    mot_axis_t *a;
    char w[MOT_REASON_LEN];

    switch (c->cmd) {
    case MOT_CMD_ABORT:
        if (mot->mode == MOT_MODE_FREE) {
            if (any_homing())
                mot->home->abort();
            for (i = 0; i < mot->num_joints; i++)
                mot->joints[i].free_tp.enable = 0;
        } else if (mot->mode == MOT_MODE_TELEOP) {
            for (i = 0; i < MOT_MAX_AXES; i++)
                mot->axis[i].tp.enable = 0;
            for (i = 0; i < mot->num_joints; i++)
                mot->joints[i].free_tp.enable = 0;
        } else {
            mot->tp->abort();
            for (i = 0; i < mot->num_joints; i++)
                mot->joints[i].free_tp.enable = 0;
        }
        mot_queue_drop();
        return MOT_ECHO_DONE;

    case MOT_CMD_FREE:
    case MOT_CMD_TELEOP:
    case MOT_CMD_COORD:
        return cmd_mode(c);

    case MOT_CMD_ENABLE:
        if (mot->enabled)
            return MOT_ECHO_DONE;
        w[0] = 0;
        if (!*mot->mp->enable)
            return reject("ENABLE: motion.enable is false");
        if (mot->tp->reset)
            mot->tp->reset();
        else
            mot->tp->abort();
        mot_line_clear();
        for (i = 0; i < mot->num_joints; i++) {
            mot->amp_on[i] = 0;
            mot->joints[i].ferror_high_mark = 0;
            mot->joints[i].flags &= ~(MOT_JOINT_ERROR | MOT_JOINT_FERROR);
        }
        mot_sync_planners();
        if (mot->mode == MOT_MODE_COORD
            && mot->tp->set_pos(&mot->carte_pos_cmd, w, sizeof(w)) < 0)
            return reject("ENABLE: the trajectory planner is not at rest "
                          "yet (%s); try again", w);
        if (mot->kins_type == KINEMATICS_INVERSE_ONLY
            && mot->mode != MOT_MODE_FREE)
            mot->mode = MOT_MODE_FREE;
        mot->error = 0;
        mot->enabled = 1;
        return MOT_ECHO_DONE;

    case MOT_CMD_DISABLE:
        if (mot->enabled)
            mot_disable();
        return MOT_ECHO_DONE;

    case MOT_CMD_ENABLE_AMPLIFIER:
    case MOT_CMD_DISABLE_AMPLIFIER:
        if ((r = bad_joint(c->joint)))
            return r;
        mot->amp_on[c->joint] = c->cmd == MOT_CMD_ENABLE_AMPLIFIER ? 1 : -1;
        return MOT_ECHO_DONE;

    case MOT_CMD_ACTIVATE_JOINT:
        if ((r = bad_joint(c->joint)))
            return r;
        mot->joints[c->joint].flags |= MOT_JOINT_ACTIVE;
        return MOT_ECHO_DONE;

    case MOT_CMD_DEACTIVATE_JOINT:
        if ((r = bad_joint(c->joint)))
            return r;
        if (mot->joints[c->joint].free_tp.active)
            return reject("DEACTIVATE_JOINT: joint %d is moving", c->joint);
        mot->joints[c->joint].flags &= ~MOT_JOINT_ACTIVE;
        return MOT_ECHO_DONE;

    case MOT_CMD_PAUSE:
        mot->tp->pause();
        return MOT_ECHO_DONE;
    case MOT_CMD_RESUME:
        mot->tp->resume();
        return MOT_ECHO_DONE;
    case MOT_CMD_STEP:
        mot->tp->step();
        return MOT_ECHO_DONE;

    case MOT_CMD_SCALE:
    case MOT_CMD_RAPID_SCALE:
        if ((r = bad_nonneg("scale", c->value)))
            return r;
        if (c->cmd == MOT_CMD_SCALE)
            mot->feed_scale = c->value;
        else
            mot->rapid_scale = c->value;
        /* the controller passes the scales (with adaptive feed and feed
           hold) to the planner at its next cycle */
        return MOT_ECHO_DONE;

    case MOT_CMD_OVERRIDE_LIMITS:
        if (c->ival != 0 && c->ival != 1)
            return reject("OVERRIDE_LIMITS takes 1 (override) or 0 "
                          "(cancel), got %d", c->ival);
        mot->override_limits = c->ival;
        mot->override_jog = -1;
        return MOT_ECHO_DONE;

    case MOT_CMD_HOME:
        return cmd_home(c);
    case MOT_CMD_UNHOME:
        return cmd_unhome(c);

    case MOT_CMD_JOG_CONT:
    case MOT_CMD_JOG_INCR:
    case MOT_CMD_JOG_ABS:
    case MOT_CMD_JOG_STOP:
        return cmd_jog(c);

    case MOT_CMD_SET_LINE:
    case MOT_CMD_SET_CIRCLE:
    case MOT_CMD_PROBE:
        return cmd_move(c);

    case MOT_CMD_SET_TELEOP_VECTOR:
        return cmd_teleop_vector(c);

    case MOT_CMD_CLEAR_PROBE_FLAG:
        mot->tp->clear_probe();
        mot->probe_tripped = 0;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_NUM_JOINTS:
        if (c->ival < 1 || c->ival > mot->num_joints)
            return reject("SET_NUM_JOINTS: %d is out of range (1..%d, the "
                          "num_joints motmod was loaded with)", c->ival,
                          mot->num_joints);
        if (mot->enabled)
            return reject("SET_NUM_JOINTS needs motion disabled");
        mot->num_joints_used = c->ival;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_JOINT_POSITION_LIMITS:
        if ((r = bad_joint(c->joint)) || (r = bad_limits(c)))
            return r;
        j = &mot->joints[c->joint];
        j->min_pos_limit = c->min_limit;
        j->max_pos_limit = c->max_limit;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_JOINT_VEL_LIMIT:
        if ((r = bad_joint(c->joint)) || (r = bad_positive("velocity",
                                                           c->vel)))
            return r;
        j = &mot->joints[c->joint];
        j->vel_limit = c->vel;
        if (j->free_tp.max_vel > c->vel)
            j->free_tp.max_vel = c->vel;
        mot_joint_limits_to_planner(c->joint);
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_JOINT_ACC_LIMIT:
        if ((r = bad_joint(c->joint)) || (r = bad_positive("acceleration",
                                                           c->acc)))
            return r;
        mot->joints[c->joint].acc_limit = c->acc;
        mot_joint_limits_to_planner(c->joint);
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_JOINT_JERK_LIMIT:
        if ((r = bad_joint(c->joint)) || (r = bad_nonneg("jerk", c->jerk)))
            return r;
        if (mot->joints[c->joint].free_tp.active)
            return reject("SET_JOINT_JERK_LIMIT: joint %d is moving",
                          c->joint);
        mot->joints[c->joint].jerk_limit = c->jerk;
        if (c->jerk > 0)
            mot->profile = FP_JERK;
        mot_joint_limits_to_planner(c->joint);
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_JOINT_MIN_FERROR:
    case MOT_CMD_SET_JOINT_MAX_FERROR:
        if ((r = bad_joint(c->joint))
            || (r = bad_nonneg("following error limit", c->value)))
            return r;
        if (c->cmd == MOT_CMD_SET_JOINT_MIN_FERROR)
            mot->joints[c->joint].min_ferror = c->value;
        else
            mot->joints[c->joint].max_ferror = c->value;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_JOINT_HOMING_PARAMS: {
        mot_home_params_t hp;
        if ((r = bad_joint(c->joint)))
            return r;
        if ((r = bad_pos("home_offset", c->home_offset))
            || (r = bad_pos("home", c->home))
            || (r = bad_pos("home_search_vel", c->home_search_vel))
            || (r = bad_pos("home_latch_vel", c->home_latch_vel))
            || (r = bad_pos("home_final_vel", c->home_final_vel)))
            return r;
        if (mot->home->is_homing(c->joint))
            return reject("SET_JOINT_HOMING_PARAMS: joint %d is homing",
                          c->joint);
        memset(&hp, 0, sizeof(hp));
        hp.home_offset = c->home_offset;
        hp.home = c->home;
        hp.home_search_vel = c->home_search_vel;
        hp.home_latch_vel = c->home_latch_vel;
        hp.home_final_vel = c->home_final_vel;
        hp.home_sequence = c->home_sequence;
        hp.volatile_home = c->volatile_home;
        hp.flags = c->home_flags;
        w[0] = 0;
        if (mot->home->set_params(c->joint, &hp, w, sizeof(w)) < 0)
            return reject("SET_JOINT_HOMING_PARAMS: %s",
                          w[0] ? w : "the homing module refused");
        mot->home_seq[c->joint] = c->home_sequence;
        return MOT_ECHO_DONE;
    }

    case MOT_CMD_SET_JOINT_BACKLASH:
        if ((r = bad_joint(c->joint)) || (r = bad_nonneg("backlash",
                                                         c->value)))
            return r;
        w[0] = 0;
        if (mot_comp_set_backlash(&mot->comp[c->joint], c->value, w,
                                  sizeof(w)) < 0)
            return reject("SET_JOINT_BACKLASH: %s", w);
        mot->joints[c->joint].backlash = c->value;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_JOINT_COMP:
    case MOT_CMD_CLEAR_JOINT_COMP:
        if ((r = bad_joint(c->joint)))
            return r;
        w[0] = 0;
        if (c->cmd == MOT_CMD_CLEAR_JOINT_COMP) {
            mot_comp_clear(&mot->comp[c->joint]);
            return MOT_ECHO_DONE;
        }
        if ((r = bad_pos("nominal position", c->comp[0]))
            || (r = bad_pos("forward trim", c->comp[1]))
            || (r = bad_pos("reverse trim", c->comp[2])))
            return r;
        if (mot_comp_add(&mot->comp[c->joint], c->comp[0], c->comp[1],
                         c->comp[2], w, sizeof(w)) < 0)
            return reject("SET_JOINT_COMP: joint %d: %s", c->joint,
                          w[0] ? w : "refused");
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_JOINT_MOTOR_OFFSET:
        if ((r = bad_joint(c->joint)) || (r = bad_pos("motor offset",
                                                      c->value)))
            return r;
        if (mot->joints[c->joint].free_tp.active)
            return reject("SET_JOINT_MOTOR_OFFSET: joint %d is moving",
                          c->joint);
        mot->joints[c->joint].motor_offset = c->value;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_AXIS_POSITION_LIMITS:
        if ((r = bad_axis(c->axis)) || (r = bad_limits(c)))
            return r;
        a = &mot->axis[c->axis];
        a->min_pos_limit = c->min_limit;
        a->max_pos_limit = c->max_limit;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_AXIS_VEL_LIMIT:
        if ((r = bad_axis(c->axis)) || (r = bad_positive("velocity",
                                                         c->vel)))
            return r;
        a = &mot->axis[c->axis];
        a->vel_limit = c->vel;
        mot_axis_limits_to_planner(c->axis);
        mot->tp->set_axis_limits(c->axis, a->vel_limit, a->acc_limit);
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_AXIS_ACC_LIMIT:
        if ((r = bad_axis(c->axis)) || (r = bad_positive("acceleration",
                                                         c->acc)))
            return r;
        a = &mot->axis[c->axis];
        a->acc_limit = c->acc;
        mot_axis_limits_to_planner(c->axis);
        mot->tp->set_axis_limits(c->axis, a->vel_limit, a->acc_limit);
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_AXIS_JERK_LIMIT:
        if ((r = bad_axis(c->axis)) || (r = bad_nonneg("jerk", c->jerk)))
            return r;
        if (mot->axis[c->axis].tp.active)
            return reject("SET_AXIS_JERK_LIMIT: axis %c is moving",
                          axis_letters[c->axis]);
        mot->axis[c->axis].jerk_limit = c->jerk;
        if (c->jerk > 0)
            mot->profile = FP_JERK;
        mot_axis_limits_to_planner(c->axis);
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_VEL:
        if ((r = bad_positive("velocity", c->vel)))
            return r;
        if (c->ini_maxvel != 0 && (r = bad_positive("ini_maxvel",
                                                    c->ini_maxvel)))
            return r;
        mot->req_vel = c->vel;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_VEL_LIMIT:
        if ((r = bad_positive("velocity", c->vel)))
            return r;
        mot->vel_limit = c->vel;
        mot->tp->set_vel_limit(c->vel);
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_ACC:
        if ((r = bad_positive("acceleration", c->acc)))
            return r;
        mot->acc_limit = c->acc;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_TERM_COND:
        if (c->ival < MOT_TERM_STOP || c->ival > MOT_TERM_BLEND)
            return reject("SET_TERM_COND: %d is not a termination "
                          "condition (0 stop, 1 exact, 2 blend)", c->ival);
        if ((r = bad_nonneg("tolerance", c->tolerance)))
            return r;
        if ((r = bad_nonneg("naive CAM tolerance (value)", c->value)))
            return r;
        mot->term_cond = c->ival;
        mot->tolerance = c->tolerance;
        mot->cam_tolerance = c->value;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_OFFSET:
        if ((r = bad_pose("tool offset", &c->pos)))
            return r;
        mot->tool_offset = c->pos;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_PROFILE:
        if (c->ival != FP_TRAPEZOID && c->ival != FP_JERK)
            return reject("SET_PROFILE: %d is not a profile (0 trapezoid, "
                          "1 jerk-limited)", c->ival);
        if (mot_moving())
            return reject("SET_PROFILE: cannot change the profile while "
                          "the machine moves");
        mot->profile = c->ival;
        for (i = 0; i < mot->num_joints; i++)
            mot_joint_limits_to_planner(i);
        for (i = 0; i < MOT_MAX_AXES; i++)
            mot_axis_limits_to_planner(i);
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_DOUT:
        if (c->index < 0 || c->index >= mot->num_dio)
            return reject("digital output %d does not exist (num_dio=%d)",
                          c->index, mot->num_dio);
        if (c->sync != 0 && c->sync != 1)
            return reject("SET_DOUT: sync must be 0 (now) or 1 (at the "
                          "start of the next move), got %d", c->sync);
        if (c->sync) {
            if (mot->tp->set_dout(c->index, c->ival ? 1 : 0, 0) < 0)
                return reject("SET_DOUT: the trajectory planner has no "
                              "room for another synchronized output");
            return MOT_ECHO_ACCEPTED;
        }
        *mot->mp->digital_out[c->index] = c->ival ? 1 : 0;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_AOUT:
        if (c->index < 0 || c->index >= mot->num_aio)
            return reject("analog output %d does not exist (num_aio=%d)",
                          c->index, mot->num_aio);
        if ((r = bad_pos("analog value", c->value)))
            return r;
        if (c->sync != 0 && c->sync != 1)
            return reject("SET_AOUT: sync must be 0 (now) or 1 (at the "
                          "start of the next move), got %d", c->sync);
        if (c->sync) {
            if (mot->tp->set_aout(c->index, c->value, 0) < 0)
                return reject("SET_AOUT: the trajectory planner has no "
                              "room for another synchronized output");
            return MOT_ECHO_ACCEPTED;
        }
        *mot->mp->analog_out[c->index] = c->value;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_FEED_HOLD_ENABLE:
    case MOT_CMD_SET_ADAPTIVE_FEED_ENABLE:
        if (c->ival != 0 && c->ival != 1)
            return reject("%s takes 1 (enable) or 0 (disable), got %d",
                          cmd_name(c->cmd), c->ival);
        if (c->cmd == MOT_CMD_SET_FEED_HOLD_ENABLE)
            mot->feed_hold_enabled = c->ival;
        else
            mot->adaptive_enabled = c->ival;
        return MOT_ECHO_DONE;

    case MOT_CMD_SET_LINEAR_UNITS:
        if ((r = bad_nonneg("millimetres per length unit", c->value)))
            return r;
        mot->linear_units = c->value;
        return MOT_ECHO_DONE;

    case MOT_CMD_SPINDLE_ON:
    case MOT_CMD_SPINDLE_OFF:
    case MOT_CMD_SPINDLE_INCREASE:
    case MOT_CMD_SPINDLE_DECREASE:
    case MOT_CMD_SPINDLE_ORIENT:
    case MOT_CMD_SPINDLE_BRAKE_ENGAGE:
    case MOT_CMD_SPINDLE_BRAKE_RELEASE:
        return cmd_spindle(c);

    case MOT_CMD_SPINDLE_SYNC_LINE:
    case MOT_CMD_RIGID_TAP:
        return cmd_move(c);

    default:
        if (c->cmd >= MOT_CMD_RESERVED_FIRST
            && c->cmd <= MOT_CMD_RESERVED_LAST)
            return reject("command %d is reserved and not implemented yet",
                          c->cmd);
        return reject("unknown command code %d", c->cmd);
    }
}

/* ---- the move queue (channel.h "The move queue") ---- */
static int queueable(int cmd)
{
    switch (cmd) {
    case MOT_CMD_SET_LINE:
    case MOT_CMD_SET_CIRCLE:
    case MOT_CMD_PROBE:
    case MOT_CMD_SPINDLE_SYNC_LINE:
    case MOT_CMD_RIGID_TAP:
    case MOT_CMD_SET_DOUT:
    case MOT_CMD_SET_AOUT:
    case MOT_CMD_SET_TERM_COND:
    case MOT_CMD_SET_VEL:
    case MOT_CMD_SET_ACC:
    case MOT_CMD_SET_VEL_LIMIT:
    case MOT_CMD_SET_FEED_HOLD_ENABLE:
    case MOT_CMD_SET_ADAPTIVE_FEED_ENABLE:
    case MOT_CMD_SPINDLE_ON:
    case MOT_CMD_SPINDLE_OFF:
    case MOT_CMD_SPINDLE_INCREASE:
    case MOT_CMD_SPINDLE_DECREASE:
    case MOT_CMD_SPINDLE_BRAKE_ENGAGE:
    case MOT_CMD_SPINDLE_BRAKE_RELEASE:
        return 1;
    }
    return 0;
}

/* records that take a place in the planner's queue */
static int is_move(int cmd)
{
    return cmd == MOT_CMD_SET_LINE || cmd == MOT_CMD_SET_CIRCLE
           || cmd == MOT_CMD_PROBE || cmd == MOT_CMD_SPINDLE_SYNC_LINE
           || cmd == MOT_CMD_RIGID_TAP || cmd == MOT_CMD_SET_DOUT
           || cmd == MOT_CMD_SET_AOUT;
}

/* moves that wait for the spindle's at-speed after a speed change */
static int waits_for_spindle(const mot_command_t *c)
{
    if (c->cmd == MOT_CMD_SPINDLE_SYNC_LINE || c->cmd == MOT_CMD_RIGID_TAP)
        return 1;
    return (c->cmd == MOT_CMD_SET_LINE || c->cmd == MOT_CMD_SET_CIRCLE)
           && (c->motion_type == MOT_MOTION_FEED
               || c->motion_type == MOT_MOTION_ARC);
}

static int spindles_at_speed(void)
{
    int i;
    for (i = 0; i < mot->num_spindles; i++)
        if (mot->spindle[i].on && mot->spindle[i].speed != 0
            && !*mot->sp[i].at_speed)
            return 0;
    return 1;
}

void mot_queue_drop(void)
{
    mot_channel_t *ch = mot->chan;
    mot->deferred_valid = 0;            /* a held mailbox move goes too */
    if (!ch)
        return;
    __atomic_store_n(&ch->q_tail, __atomic_load_n(&ch->q_head,
                                                  __ATOMIC_ACQUIRE),
                     __ATOMIC_RELEASE);
}

static void queue_failed(mot_channel_t *ch, const mot_command_t *c,
                         const char *reason)
{
    ch->q_err_cmd = c->cmd;
    ch->q_err_id = c->id;
    ch->q_err_line = c->line;
    snprintf(ch->q_err_reason, sizeof(ch->q_err_reason), "%s", reason);
    mot_post("queued %s (id %d, line %d) rejected: %s; the rest of the "
             "queue is dropped", cmd_name(c->cmd), c->id, c->line, reason);
    __atomic_store_n(&ch->q_err_count, ch->q_err_count + 1,
                     __ATOMIC_RELEASE);
}

static void drain_queue(mot_channel_t *ch)
{
    uint32_t head = __atomic_load_n(&ch->q_head, __ATOMIC_ACQUIRE);
    uint32_t tail = ch->q_tail;
    char w[MOT_REASON_LEN];
    mot_command_t c;
    int n = 0, st;

    if (head == tail)
        return;
    if (head - tail > MOT_QUEUE_SIZE) {
        mot_post("the move queue holds %u records, more than its %d "
                 "places (a client broke the protocol): dropped",
                 head - tail, MOT_QUEUE_SIZE);
        memset(&c, 0, sizeof(c));
        queue_failed(ch, &c, "the move queue overflowed");
        __atomic_store_n(&ch->q_tail, head, __ATOMIC_RELEASE);
        return;
    }
    while (tail != head && n < MOT_QUEUE_BURST) {
        const mot_command_t *q = &ch->queue[tail % MOT_QUEUE_SIZE];
        if (q->epoch != ch->q_err_count) {
            tail++;                     /* after a rejection: dropped */
            continue;
        }
        if (is_move(q->cmd) && mot->tp->queue_space() <= 0)
            break;                      /* the planner is full */
        if (mot->wait_at_speed && waits_for_spindle(q)) {
            /* the first feed move after a spindle start or speed change
               starts at rest with the spindles at speed: hold the queue
               until the planner has run out and at-speed is true */
            if (!mot->tp_done || !spindles_at_speed())
                break;
            mot->wait_at_speed = 0;
        }
        memcpy(&c, q, sizeof(c));
        why = w;
        whylen = sizeof(w);
        w[0] = 0;
        if (queueable(c.cmd))
            st = run_command(&c);
        else
            st = reject("%s cannot be queued (only moves and what must "
                        "keep its order with them)", cmd_name(c.cmd));
        tail++;
        n++;
        if (st == MOT_ECHO_REJECTED) {
            queue_failed(ch, &c, w[0] ? w : "no reason given");
            /* the records after it have the old epoch: dropped in the
               next cycles (or right now) */
        }
    }
    __atomic_store_n(&ch->q_tail, tail, __ATOMIC_RELEASE);
}

/* hand the held mailbox move to the planner once its wait is over (or
   was cancelled by SPINDLE_OFF); a refusal then is posted */
static void run_deferred(void)
{
    char w[MOT_REASON_LEN];

    if (!mot->deferred_valid)
        return;
    if (!mot->enabled || mot->mode != MOT_MODE_COORD) {
        mot->deferred_valid = 0;
        return;
    }
    if (mot->wait_at_speed && (!mot->tp_done || !spindles_at_speed()))
        return;
    mot->deferred_valid = 0;
    mot->wait_at_speed = 0;
    why = w;
    whylen = sizeof(w);
    w[0] = 0;
    if (run_command(&mot->deferred) == MOT_ECHO_REJECTED)
        mot_post("%s (id %d, line %d), held until the spindle was at "
                 "speed, was refused: %s", cmd_name(mot->deferred.cmd),
                 mot->deferred.id, mot->deferred.line, w);
}

void mot_command_handler(void *arg, long period)
{
    mot_channel_t *ch = mot->chan;
    mot_command_t c;
    uint32_t seq;
    int st;

    (void)arg;
    (void)period;
    if (!ch)
        return;
    run_deferred();
    seq = __atomic_load_n(&ch->cmd_seq, __ATOMIC_ACQUIRE);
    if (seq == mot->last_seq) {
        drain_queue(ch);
        return;
    }
    memcpy(&c, (const void *)&ch->command, sizeof(c));
    mot->last_seq = seq;

    why = ch->echo_reason;
    whylen = sizeof(ch->echo_reason);
    why[0] = 0;
    if (mot->wait_at_speed && waits_for_spindle(&c) && mot->enabled
        && mot->mode == MOT_MODE_COORD) {
        /* a feed move after a spindle start runs once the planner has
           run out and the spindles are at speed: answer now (ABORT must
           get through meanwhile) and hold the move */
        tp_move_t m;
        if (mot->deferred_valid)
            st = reject("%s: a feed move already waits for the spindle to "
                        "reach speed", cmd_name(c.cmd));
        else if ((st = check_move(&c, &m)) == MOT_ECHO_REJECTED)
            ;                           /* checked now, not after the wait */
        else {
            mot->deferred = c;
            mot->deferred_valid = 1;
            st = MOT_ECHO_ACCEPTED;
        }
    } else
        st = run_command(&c);
    if (st != MOT_ECHO_REJECTED)
        why[0] = 0;
    ch->echo_status = st;
    ch->echo_cmd = c.cmd;
    __atomic_store_n(&ch->echo_seq, seq, __ATOMIC_RELEASE);
    drain_queue(ch);
}
