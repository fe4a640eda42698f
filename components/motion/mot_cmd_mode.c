/*
 * mot_cmd_mode.c - the command handlers of motion's state and modes:
 * ABORT, FREE / TELEOP / COORD, ENABLE, DISABLE, the amplifiers,
 * (DE)ACTIVATE_JOINT and OVERRIDE_LIMITS (mot_command.c dispatches).
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

static int first_moving(mot_t *mot)
{
    int i;
    for (i = 0; i < mot->num_joints_used; i++)
        if (mot->joints[i].free_tp.active)
            return i;
    return -1;
}

/* ---- modes ---- */
int mot_cmd_mode(mot_t *mot, const mot_command_t *c)
{
    int want = c->cmd == MOT_CMD_FREE ? MOT_MODE_FREE
               : c->cmd == MOT_CMD_TELEOP ? MOT_MODE_TELEOP : MOT_MODE_COORD;
    int j;

    if (mot->mode == want)
        return MOT_ECHO_DONE;
    if (mot_any_homing(mot))
        return mot_reject(mot, "%s: cannot change mode while a joint is "
                          "homing", mot_cmd_name(c->cmd));
    if (mot_moving(mot)) {
        j = first_moving(mot);
        if (j >= 0)
            return mot_reject(mot, "%s: cannot change mode while joint %d "
                              "moves (now %s)", mot_cmd_name(c->cmd), j,
                              mot_mode_names[mot->mode]);
        return mot_reject(mot, "%s: cannot change mode while the machine "
                          "moves (now %s)", mot_cmd_name(c->cmd),
                          mot_mode_names[mot->mode]);
    }
    if (want != MOT_MODE_FREE) {
        if (mot->kins_type != KINEMATICS_IDENTITY && !mot_all_homed(mot))
            return mot_reject(mot, "%s needs all joints homed (the "
                              "kinematics are not identity)",
                              mot_cmd_name(c->cmd));
        if (mot->kins_type == KINEMATICS_FORWARD_ONLY)
            return mot_reject(mot, "%s needs inverse kinematics (the "
                              "kinematics module has forward only)",
                              mot_cmd_name(c->cmd));
    }
    mot_sync_planners(mot);
    if (want == MOT_MODE_COORD) {
        char w[MOT_REASON_LEN];
        w[0] = 0;
        if (mot->tp->set_pos(&mot->carte_pos_cmd, w, sizeof(w)) < 0)
            return mot_reject(mot, "COORD: the trajectory planner refused the "
                              "present position: %s", w);
        mot->tp_done = 1;
        mot->queue_depth = 0;
    }
    mot->mode = want;
    return MOT_ECHO_DONE;
}

/* ---- handlers of the dispatch table (mot_command.c) ---- */

/* ABORT */
int mot_cmd_abort(mot_t *mot, const mot_command_t *c)
{
    int i;

    if (mot->mode == MOT_MODE_FREE) {
        if (mot_any_homing(mot))
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
    mot_queue_drop(mot);
    return MOT_ECHO_DONE;
}

/* ENABLE */
int mot_cmd_enable(mot_t *mot, const mot_command_t *c)
{
    int i;
    char w[MOT_REASON_LEN];

    if (mot->enabled)
        return MOT_ECHO_DONE;
    w[0] = 0;
    if (!*mot->mp->enable)
        return mot_reject(mot, "ENABLE: motion.enable is false");
    if (mot->tp->reset)
        mot->tp->reset();
    else
        mot->tp->abort();
    mot_line_clear(mot);
    for (i = 0; i < mot->num_joints; i++) {
        mot->amp_on[i] = 0;
        mot->joints[i].ferror_high_mark = 0;
        mot->joints[i].flags &= ~(MOT_JOINT_ERROR | MOT_JOINT_FERROR);
    }
    mot_sync_planners(mot);
    if (mot->mode == MOT_MODE_COORD
        && mot->tp->set_pos(&mot->carte_pos_cmd, w, sizeof(w)) < 0)
        return mot_reject(mot, "ENABLE: the trajectory planner is not at rest "
                          "yet (%s); try again", w);
    if (mot->kins_type == KINEMATICS_INVERSE_ONLY
        && mot->mode != MOT_MODE_FREE)
        mot->mode = MOT_MODE_FREE;
    mot->error = 0;
    mot->enabled = 1;
    return MOT_ECHO_DONE;
}

/* DISABLE */
int mot_cmd_disable(mot_t *mot, const mot_command_t *c)
{
    if (mot->enabled)
        mot_disable(mot);
    return MOT_ECHO_DONE;
}

/* ENABLE_AMPLIFIER, DISABLE_AMPLIFIER */
int mot_cmd_amplifier(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_joint(mot, c->joint)))
        return r;
    mot->amp_on[c->joint] = c->cmd == MOT_CMD_ENABLE_AMPLIFIER ? 1 : -1;
    return MOT_ECHO_DONE;
}

/* ACTIVATE_JOINT */
int mot_cmd_activate_joint(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_joint(mot, c->joint)))
        return r;
    mot->joints[c->joint].flags |= MOT_JOINT_ACTIVE;
    return MOT_ECHO_DONE;
}

/* DEACTIVATE_JOINT */
int mot_cmd_deactivate_joint(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_joint(mot, c->joint)))
        return r;
    if (mot->joints[c->joint].free_tp.active)
        return mot_reject(mot, "DEACTIVATE_JOINT: joint %d is moving",
                          c->joint);
    mot->joints[c->joint].flags &= ~MOT_JOINT_ACTIVE;
    return MOT_ECHO_DONE;
}

/* OVERRIDE_LIMITS */
int mot_cmd_override_limits(mot_t *mot, const mot_command_t *c)
{
    if (c->ival != 0 && c->ival != 1)
        return mot_reject(mot, "OVERRIDE_LIMITS takes 1 (override) or 0 "
                          "(cancel), got %d", c->ival);
    mot->override_limits = c->ival;
    mot->override_jog = -1;
    return MOT_ECHO_DONE;
}
