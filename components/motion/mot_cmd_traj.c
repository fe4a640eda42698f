/*
 * mot_cmd_traj.c - the commands of the coordinated (trajectory planner)
 * mode: the moves (SET_LINE, SET_CIRCLE, PROBE, SPINDLE_SYNC_LINE,
 * RIGID_TAP), CLEAR_PROBE_FLAG, PAUSE / RESUME / STEP, the overrides and
 * feed controls, SET_VEL / SET_VEL_LIMIT / SET_ACC, SET_TERM_COND,
 * SET_OFFSET and the (synchronized) outputs SET_DOUT / SET_AOUT.
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

static int move_args(mot_t *mot, const mot_command_t *c, tp_move_t *m)
{
    int r;
    const char *name = mot_cmd_name(c->cmd);

    if (mot->mode != MOT_MODE_COORD)
        return mot_reject(mot, "%s needs coord mode (now %s)", name,
                          mot_mode_names[mot->mode]);
    if (!mot->enabled)
        return mot_reject(mot, "%s needs motion enabled", name);
    if ((r = mot_bad_pose(mot, "end point", &c->pos)))
        return r;
    if ((r = mot_bad_positive(mot, "velocity", c->vel)))
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
        if ((r = mot_bad_spindle(mot, n)))
            return r;
        if ((r = mot_bad_positive(mot, "pitch", c->pitch)))
            return r;
        if (!mot->spindle[n].on || mot->spindle[n].speed == 0)
            return mot_reject(mot, "%s needs spindle %d turning (SPINDLE_ON "
                              "first)", name, n);
        m->sync = TP_SYNC_POSITION;
        m->spindle = n;
        m->pitch = c->pitch;
    }
    if (m->ini_maxvel == 0)
        m->ini_maxvel = mot->vel_limit;
    if (m->acc == 0)
        m->acc = mot->acc_limit;
    if ((r = mot_bad_positive(mot, "maximum velocity (ini_maxvel, or "
                              "SET_VEL_LIMIT when 0)", m->ini_maxvel)))
        return r;
    if ((r = mot_bad_positive(mot, "acceleration (acc, or SET_ACC when 0)",
                              m->acc)))
        return r;
    if ((r = mot_bad_nonneg(mot, "jerk", m->jerk)))
        return r;
    if (c->motion_type < 0 || c->motion_type > MOT_MOTION_INDEXROTARY)
        return mot_reject(mot, "motion type %d is not one of 0..6",
                          c->motion_type);
    /* the end point must be inside the axes' limits (when they apply) */
    if (mot->all_homed_c) {
        int i;
        for (i = 0; i < MOT_MAX_AXES; i++) {
            mot_axis_t *a = &mot->axis[i];
            double v = *emcpose_axis((EmcPose *)&c->pos, i);
            if (v > a->max_pos_limit || v < a->min_pos_limit)
                return mot_reject(mot, "%s: the end point %c=%g is outside "
                                  "the axis limits %g..%g", name,
                                  mot_axis_letters[i], v, a->min_pos_limit,
                                  a->max_pos_limit);
        }
    }
    return 0;
}

/* all checks of a move command before it goes to the planner */
int mot_check_move(mot_t *mot, const mot_command_t *c, tp_move_t *m)
{
    int r;

    if ((r = move_args(mot, c, m)))
        return r;
    if (c->cmd == MOT_CMD_SET_CIRCLE) {
        if ((r = mot_bad_cart(mot, "center", &c->center)))
            return r;
        if ((r = mot_bad_cart(mot, "normal", &c->normal)))
            return r;
        if (c->normal.x == 0 && c->normal.y == 0 && c->normal.z == 0)
            return mot_reject(mot, "SET_CIRCLE: the normal must not be (0, "
                              "0, 0)");
    } else if (c->cmd == MOT_CMD_PROBE && mot->probe_tripped) {
        return mot_reject(mot, "PROBE: the probe flag is still set (send "
                          "CLEAR_PROBE_FLAG first)");
    } else if (c->cmd == MOT_CMD_RIGID_TAP && !mot->tp->add_rigid_tap) {
        return mot_reject(mot, "RIGID_TAP: the trajectory planner cannot do "
                          "rigid tapping");
    }
    return 0;
}

int mot_cmd_move(mot_t *mot, const mot_command_t *c)
{
    tp_move_t m;
    char w[MOT_REASON_LEN];
    int r;

    if ((r = mot_check_move(mot, c, &m)))
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
        return mot_reject(mot, "%s: %s", mot_cmd_name(c->cmd),
                          w[0] ? w : "the trajectory planner refused it");
    mot->tp_done = 0;
    mot_line_push(mot, c->id, c->line, c->vel);
    return MOT_ECHO_ACCEPTED;
}

/* ---- handlers of the dispatch table (mot_command.c) ---- */

/* CLEAR_PROBE_FLAG */
int mot_cmd_clear_probe_flag(mot_t *mot, const mot_command_t *c)
{
    mot->tp->clear_probe();
    mot->probe_tripped = 0;
    return MOT_ECHO_DONE;
}

/* PAUSE */
int mot_cmd_pause(mot_t *mot, const mot_command_t *c)
{
    mot->tp->pause();
    return MOT_ECHO_DONE;
}

/* RESUME */
int mot_cmd_resume(mot_t *mot, const mot_command_t *c)
{
    mot->tp->resume();
    return MOT_ECHO_DONE;
}

/* STEP */
int mot_cmd_step(mot_t *mot, const mot_command_t *c)
{
    mot->tp->step();
    return MOT_ECHO_DONE;
}

/* SCALE, RAPID_SCALE */
int mot_cmd_scale(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_nonneg(mot, "scale", c->value)))
        return r;
    if (c->cmd == MOT_CMD_SCALE)
        mot->feed_scale = c->value;
    else
        mot->rapid_scale = c->value;
    /* the controller passes the scales (with adaptive feed and feed
       hold) to the planner at its next cycle */
    return MOT_ECHO_DONE;
}

/* SET_VEL */
int mot_cmd_set_vel(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_positive(mot, "velocity", c->vel)))
        return r;
    if (c->ini_maxvel != 0 && (r = mot_bad_positive(mot, "ini_maxvel",
                                                    c->ini_maxvel)))
        return r;
    mot->req_vel = c->vel;
    return MOT_ECHO_DONE;
}

/* SET_VEL_LIMIT */
int mot_cmd_set_vel_limit(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_positive(mot, "velocity", c->vel)))
        return r;
    mot->vel_limit = c->vel;
    mot->tp->set_vel_limit(c->vel);
    return MOT_ECHO_DONE;
}

/* SET_ACC */
int mot_cmd_set_acc(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_positive(mot, "acceleration", c->acc)))
        return r;
    mot->acc_limit = c->acc;
    return MOT_ECHO_DONE;
}

/* SET_TERM_COND */
int mot_cmd_set_term_cond(mot_t *mot, const mot_command_t *c)
{
    int r;

    if (c->ival < MOT_TERM_STOP || c->ival > MOT_TERM_BLEND)
        return mot_reject(mot, "SET_TERM_COND: %d is not a termination "
                          "condition (0 stop, 1 exact, 2 blend)", c->ival);
    if ((r = mot_bad_nonneg(mot, "tolerance", c->tolerance)))
        return r;
    if ((r = mot_bad_nonneg(mot, "naive CAM tolerance (value)", c->value)))
        return r;
    mot->term_cond = c->ival;
    mot->tolerance = c->tolerance;
    mot->cam_tolerance = c->value;
    return MOT_ECHO_DONE;
}

/* SET_OFFSET */
int mot_cmd_set_offset(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_pose(mot, "tool offset", &c->pos)))
        return r;
    mot->tool_offset = c->pos;
    return MOT_ECHO_DONE;
}

/* SET_DOUT */
int mot_cmd_set_dout(mot_t *mot, const mot_command_t *c)
{
    if (c->index < 0 || c->index >= mot->num_dio)
        return mot_reject(mot, "digital output %d does not exist (num_dio=%d)",
                          c->index, mot->num_dio);
    if (c->sync != 0 && c->sync != 1)
        return mot_reject(mot, "SET_DOUT: sync must be 0 (now) or 1 (at the "
                          "start of the next move), got %d", c->sync);
    if (c->sync) {
        if (mot->tp->set_dout(c->index, c->ival ? 1 : 0, 0) < 0)
            return mot_reject(mot, "SET_DOUT: the trajectory planner has no "
                              "room for another synchronized output");
        return MOT_ECHO_ACCEPTED;
    }
    *mot->mp->digital_out[c->index] = c->ival ? 1 : 0;
    return MOT_ECHO_DONE;
}

/* SET_AOUT */
int mot_cmd_set_aout(mot_t *mot, const mot_command_t *c)
{
    int r;

    if (c->index < 0 || c->index >= mot->num_aio)
        return mot_reject(mot, "analog output %d does not exist (num_aio=%d)",
                          c->index, mot->num_aio);
    if ((r = mot_bad_pos(mot, "analog value", c->value)))
        return r;
    if (c->sync != 0 && c->sync != 1)
        return mot_reject(mot, "SET_AOUT: sync must be 0 (now) or 1 (at the "
                          "start of the next move), got %d", c->sync);
    if (c->sync) {
        if (mot->tp->set_aout(c->index, c->value, 0) < 0)
            return mot_reject(mot, "SET_AOUT: the trajectory planner has no "
                              "room for another synchronized output");
        return MOT_ECHO_ACCEPTED;
    }
    *mot->mp->analog_out[c->index] = c->value;
    return MOT_ECHO_DONE;
}

/* SET_FEED_HOLD_ENABLE, SET_ADAPTIVE_FEED_ENABLE */
int mot_cmd_feed_enables(mot_t *mot, const mot_command_t *c)
{
    if (c->ival != 0 && c->ival != 1)
        return mot_reject(mot, "%s takes 1 (enable) or 0 (disable), got %d",
                          mot_cmd_name(c->cmd), c->ival);
    if (c->cmd == MOT_CMD_SET_FEED_HOLD_ENABLE)
        mot->feed_hold_enabled = c->ival;
    else
        mot->adaptive_enabled = c->ival;
    return MOT_ECHO_DONE;
}
