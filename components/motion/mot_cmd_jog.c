/*
 * mot_cmd_jog.c - the jog commands (JOG_CONT, JOG_INCR, JOG_ABS,
 * JOG_STOP) of joints in free mode and axes in teleop mode, and
 * SET_TELEOP_VECTOR.
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
#include "mot_cmd.h"

/* ---- jogs ---- */
static double jog_speed(mot_t *mot, double v, double lim)
{
    v = fabs(v) * mot->feed_scale;
    return v > lim ? lim : v;
}

/* the jog starts: remember it for OVERRIDE_LIMITS */
static void jog_started(mot_t *mot, int who)
{
    if (mot->override_limits && mot->override_jog < 0)
        mot->override_jog = who;
}

static int cmd_jog_joint(mot_t *mot, const mot_command_t *c)
{
    const char *name = mot_cmd_name(c->cmd);
    int n = c->joint, homed, r;
    mot_joint_t *j;
    double t, spd, dir;

    if (mot->mode != MOT_MODE_FREE)
        return mot_reject(mot, "%s of a joint needs free mode (now %s)", name,
                          mot_mode_names[mot->mode]);
    if ((r = mot_bad_joint(mot, n)))
        return r;
    j = &mot->joints[n];
    if (c->cmd == MOT_CMD_JOG_STOP) {
        j->free_tp.enable = 0;
        return MOT_ECHO_DONE;
    }
    if (!mot->enabled)
        return mot_reject(mot, "%s needs motion enabled", name);
    if (mot_any_homing(mot))
        return mot_reject(mot, "%s: cannot jog while a joint is homing", name);
    if (*mot->mp->jog_inhibit)
        return mot_reject(mot, "%s: jogging is inhibited (motion.jog-inhibit "
                          "is true)", name);
    if (!(j->flags & MOT_JOINT_ACTIVE))
        return mot_reject(mot, "%s: joint %d is not active", name, n);
    if (mot->home_seq[n] < 0 && mot->home_seq[n] != HOME_SEQUENCE_NONE)
        return mot_reject(mot, "%s: joint %d homes in a synchronized sequence "
                          "(HOME_SEQUENCE %d) and cannot be jogged alone",
                          name, n, mot->home_seq[n]);
    homed = mot->home->is_homed(n);

    if (c->cmd == MOT_CMD_JOG_CONT) {
        if (!isfinite(c->vel) || c->vel == 0)
            return mot_reject(mot, "velocity must be a nonzero number, got %g",
                              c->vel);
        dir = c->vel > 0 ? 1 : -1;
        t = homed ? (dir > 0 ? j->max_pos_limit : j->min_pos_limit)
                  : j->pos_cmd + dir * MOT_FAR;
    } else {
        if ((r = mot_bad_positive(mot, "velocity", c->vel)))
            return r;
        if (c->cmd == MOT_CMD_JOG_INCR) {
            if ((r = mot_bad_pos(mot, "increment", c->offset)))
                return r;
            t = (mot->jog_kind[n] == MOT_JOG_INCR && j->free_tp.enable)
                ? j->free_tp.target : j->pos_cmd;
            t += c->offset;
        } else {
            if ((r = mot_bad_pos(mot, "position", c->offset)))
                return r;
            t = c->offset;
        }
        dir = t > j->pos_cmd ? 1 : (t < j->pos_cmd ? -1 : 0);
    }
    if (homed && c->cmd == MOT_CMD_JOG_ABS) {
        /* an absolute jog names a position: one beyond a soft limit is
           refused, not cut short at the limit without a word (an
           increment or a continuous jog still ends at the limit, as the
           reference's "terminated at the soft limit") */
        if (t > j->max_pos_limit)
            return mot_reject(mot, "%s: joint %d target %g is beyond its "
                              "positive soft limit (%g)", name, n, t,
                              j->max_pos_limit);
        if (t < j->min_pos_limit)
            return mot_reject(mot, "%s: joint %d target %g is beyond its "
                              "negative soft limit (%g)", name, n, t,
                              j->min_pos_limit);
    }
    if (homed) {
        if (dir > 0 && j->pos_cmd >= j->max_pos_limit)
            return mot_reject(mot, "%s: joint %d is at its positive soft "
                              "limit (%g)", name, n, j->max_pos_limit);
        if (dir < 0 && j->pos_cmd <= j->min_pos_limit)
            return mot_reject(mot, "%s: joint %d is at its negative soft "
                              "limit (%g)", name, n, j->min_pos_limit);
        if (t > j->max_pos_limit)
            t = j->max_pos_limit;
        if (t < j->min_pos_limit)
            t = j->min_pos_limit;
    }
    /* a limit switch already hit (while limits are overridden): only
       away from it */
    if (dir > 0 && j->pos_limit_sw)
        return mot_reject(mot, "%s: joint %d is on its positive hard limit "
                          "switch", name, n);
    if (dir < 0 && j->neg_limit_sw)
        return mot_reject(mot, "%s: joint %d is on its negative hard limit "
                          "switch", name, n);
    spd = jog_speed(mot, c->vel, j->vel_limit);
    if (!(spd > 0))
        return mot_reject(mot, "%s: the jog speed is 0 (feed scale %g)", name,
                          mot->feed_scale);
    mot_joint_limits_to_planner(mot, n);
    j->free_tp.max_vel = spd;
    j->free_tp.target = t;
    j->free_tp.enable = 1;
    mot->jog_kind[n] = c->cmd == MOT_CMD_JOG_CONT ? MOT_JOG_CONT
                       : c->cmd == MOT_CMD_JOG_INCR ? MOT_JOG_INCR
                       : MOT_JOG_ABS;
    mot->jog_vel[n] = spd;
    jog_started(mot, n);
    return MOT_ECHO_ACCEPTED;
}

static double axis_clamp(mot_t *mot, int n, double t, int *limited)
{
    mot_axis_t *a = &mot->axis[n];
    *limited = 0;
    if (!mot_all_homed(mot))
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

static int cmd_jog_axis(mot_t *mot, const mot_command_t *c)
{
    const char *name = mot_cmd_name(c->cmd);
    int n = c->axis, r, lim;
    mot_axis_t *a;
    double t, spd, dir, pos;

    if (mot->mode != MOT_MODE_TELEOP)
        return mot_reject(mot, "%s of an axis needs teleop mode (now %s)",
                          name, mot_mode_names[mot->mode]);
    if ((r = mot_bad_axis(mot, n)))
        return r;
    a = &mot->axis[n];
    if (c->cmd == MOT_CMD_JOG_STOP) {
        a->tp.enable = 0;
        return MOT_ECHO_DONE;
    }
    if (!mot->enabled)
        return mot_reject(mot, "%s needs motion enabled", name);
    if (*mot->mp->jog_inhibit)
        return mot_reject(mot, "%s: jogging is inhibited (motion.jog-inhibit "
                          "is true)", name);
    pos = a->tp.pos;
    if (c->cmd == MOT_CMD_JOG_CONT) {
        if (!isfinite(c->vel) || c->vel == 0)
            return mot_reject(mot, "velocity must be a nonzero number, got %g",
                              c->vel);
        dir = c->vel > 0 ? 1 : -1;
        t = pos + dir * MOT_FAR;
    } else {
        if ((r = mot_bad_positive(mot, "velocity", c->vel)))
            return r;
        if (c->cmd == MOT_CMD_JOG_INCR) {
            if ((r = mot_bad_pos(mot, "increment", c->offset)))
                return r;
            t = (a->jog == MOT_JOG_INCR && a->tp.enable) ? a->tp.target
                                                          : pos;
            t += c->offset;
        } else {
            if ((r = mot_bad_pos(mot, "position", c->offset)))
                return r;
            t = c->offset;
        }
        dir = t > pos ? 1 : (t < pos ? -1 : 0);
    }
    if (mot_all_homed(mot) && c->cmd == MOT_CMD_JOG_ABS) {
        /* as for a joint: an absolute target beyond a limit is refused */
        if (t > a->max_pos_limit)
            return mot_reject(mot, "%s: axis %c target %g is beyond its "
                              "positive limit (%g)", name,
                              mot_axis_letters[n], t, a->max_pos_limit);
        if (t < a->min_pos_limit)
            return mot_reject(mot, "%s: axis %c target %g is beyond its "
                              "negative limit (%g)", name,
                              mot_axis_letters[n], t, a->min_pos_limit);
    }
    t = axis_clamp(mot, n, t, &lim);
    if (mot_all_homed(mot)) {
        if (dir > 0 && pos >= a->max_pos_limit)
            return mot_reject(mot, "%s: axis %c is at its positive limit (%g)",
                              name, mot_axis_letters[n], a->max_pos_limit);
        if (dir < 0 && pos <= a->min_pos_limit)
            return mot_reject(mot, "%s: axis %c is at its negative limit (%g)",
                              name, mot_axis_letters[n], a->min_pos_limit);
    }
    spd = jog_speed(mot, c->vel, a->vel_limit);
    if (!(spd > 0))
        return mot_reject(mot, "%s: the jog speed is 0 (feed scale %g)", name,
                          mot->feed_scale);
    mot_axis_limits_to_planner(mot, n);
    a->tp.max_vel = spd;
    a->tp.target = t;
    a->tp.enable = 1;
    a->jog = c->cmd == MOT_CMD_JOG_CONT ? MOT_JOG_CONT
             : c->cmd == MOT_CMD_JOG_INCR ? MOT_JOG_INCR : MOT_JOG_ABS;
    a->req_vel = spd;
    jog_started(mot, 100 + n);
    return MOT_ECHO_ACCEPTED;
}

int mot_cmd_jog(mot_t *mot, const mot_command_t *c)
{
    if (c->joint >= 0)
        return cmd_jog_joint(mot, c);
    if (c->joint == -1 && c->axis >= 0)
        return cmd_jog_axis(mot, c);
    if (c->joint < -1)
        return mot_reject(mot, "joint %d does not exist (num_joints=%d)",
                          c->joint, mot->num_joints_used);
    return mot_reject(mot, "%s needs a joint (free mode) or an axis with "
                      "joint -1 (teleop mode)", mot_cmd_name(c->cmd));
}

int mot_cmd_teleop_vector(mot_t *mot, const mot_command_t *c)
{
    int i, r, lim;

    if (mot->mode != MOT_MODE_TELEOP)
        return mot_reject(mot, "SET_TELEOP_VECTOR needs teleop mode (now %s)",
                          mot_mode_names[mot->mode]);
    if (!mot->enabled)
        return mot_reject(mot, "SET_TELEOP_VECTOR needs motion enabled");
    if ((r = mot_bad_pose(mot, "velocity of axis", &c->pos)))
        return r;
    for (i = 0; i < MOT_MAX_AXES; i++) {
        mot_axis_t *a = &mot->axis[i];
        double v = *emcpose_axis((EmcPose *)&c->pos, i);
        if (v == 0) {
            a->tp.enable = 0;
            continue;
        }
        mot_axis_limits_to_planner(mot, i);
        a->tp.max_vel = jog_speed(mot, v, a->vel_limit);
        a->tp.target = axis_clamp(mot, i,
                                  a->tp.pos + (v > 0 ? MOT_FAR : -MOT_FAR),
                                  &lim);
        a->tp.enable = 1;
        a->jog = MOT_JOG_NONE;
    }
    return MOT_ECHO_ACCEPTED;
}
