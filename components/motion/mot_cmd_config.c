/*
 * mot_cmd_config.c - the configuration commands of joints, axes and the
 * machine: SET_NUM_JOINTS, SET_JOINT_*, (CLEAR_)JOINT_COMP, SET_AXIS_*,
 * SET_PROFILE and SET_LINEAR_UNITS.
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

/* ---- handlers of the dispatch table (mot_command.c) ---- */

/* SET_NUM_JOINTS */
int mot_cmd_set_num_joints(mot_t *mot, const mot_command_t *c)
{
    if (c->ival < 1 || c->ival > mot->num_joints)
        return mot_reject(mot, "SET_NUM_JOINTS: %d is out of range (1..%d, "
                          "the num_joints motmod was loaded with)", c->ival,
                          mot->num_joints);
    if (mot->enabled)
        return mot_reject(mot, "SET_NUM_JOINTS needs motion disabled");
    mot->num_joints_used = c->ival;
    return MOT_ECHO_DONE;
}

/* SET_JOINT_POSITION_LIMITS */
int mot_cmd_set_joint_position_limits(mot_t *mot, const mot_command_t *c)
{
    int r;
    mot_joint_t *j;

    if ((r = mot_bad_joint(mot, c->joint)) || (r = mot_bad_limits(mot, c)))
        return r;
    j = &mot->joints[c->joint];
    j->min_pos_limit = c->min_limit;
    j->max_pos_limit = c->max_limit;
    return MOT_ECHO_DONE;
}

/* SET_JOINT_VEL_LIMIT */
int mot_cmd_set_joint_vel_limit(mot_t *mot, const mot_command_t *c)
{
    int r;
    mot_joint_t *j;

    if ((r = mot_bad_joint(mot, c->joint)) ||
        (r = mot_bad_positive(mot, "velocity", c->vel)))
        return r;
    j = &mot->joints[c->joint];
    j->vel_limit = c->vel;
    if (j->free_tp.max_vel > c->vel)
        j->free_tp.max_vel = c->vel;
    mot_joint_limits_to_planner(mot, c->joint);
    return MOT_ECHO_DONE;
}

/* SET_JOINT_ACC_LIMIT */
int mot_cmd_set_joint_acc_limit(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_joint(mot, c->joint)) ||
        (r = mot_bad_positive(mot, "acceleration", c->acc)))
        return r;
    mot->joints[c->joint].acc_limit = c->acc;
    mot_joint_limits_to_planner(mot, c->joint);
    return MOT_ECHO_DONE;
}

/* SET_JOINT_JERK_LIMIT */
int mot_cmd_set_joint_jerk_limit(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_joint(mot, c->joint)) ||
        (r = mot_bad_nonneg(mot, "jerk", c->jerk)))
        return r;
    if (mot->joints[c->joint].free_tp.active)
        return mot_reject(mot, "SET_JOINT_JERK_LIMIT: joint %d is moving",
                          c->joint);
    mot->joints[c->joint].jerk_limit = c->jerk;
    if (c->jerk > 0)
        mot->profile = FP_JERK;
    mot_joint_limits_to_planner(mot, c->joint);
    return MOT_ECHO_DONE;
}

/* SET_JOINT_MIN_FERROR, SET_JOINT_MAX_FERROR */
int mot_cmd_set_joint_ferror(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_joint(mot, c->joint))
        || (r = mot_bad_nonneg(mot, "following error limit", c->value)))
        return r;
    if (c->cmd == MOT_CMD_SET_JOINT_MIN_FERROR)
        mot->joints[c->joint].min_ferror = c->value;
    else
        mot->joints[c->joint].max_ferror = c->value;
    return MOT_ECHO_DONE;
}

/* SET_JOINT_BACKLASH */
int mot_cmd_set_joint_backlash(mot_t *mot, const mot_command_t *c)
{
    int r;
    char w[MOT_REASON_LEN];

    if ((r = mot_bad_joint(mot, c->joint)) ||
        (r = mot_bad_nonneg(mot, "backlash", c->value)))
        return r;
    w[0] = 0;
    if (mot_comp_set_backlash(&mot->comp[c->joint], c->value, w,
                              sizeof(w)) < 0)
        return mot_reject(mot, "SET_JOINT_BACKLASH: %s", w);
    mot->joints[c->joint].backlash = c->value;
    return MOT_ECHO_DONE;
}

/* SET_JOINT_COMP, CLEAR_JOINT_COMP */
int mot_cmd_joint_comp(mot_t *mot, const mot_command_t *c)
{
    int r;
    char w[MOT_REASON_LEN];

    if ((r = mot_bad_joint(mot, c->joint)))
        return r;
    w[0] = 0;
    if (c->cmd == MOT_CMD_CLEAR_JOINT_COMP) {
        mot_comp_clear(&mot->comp[c->joint]);
        return MOT_ECHO_DONE;
    }
    if ((r = mot_bad_pos(mot, "nominal position", c->comp[0]))
        || (r = mot_bad_pos(mot, "forward trim", c->comp[1]))
        || (r = mot_bad_pos(mot, "reverse trim", c->comp[2])))
        return r;
    if (mot_comp_add(&mot->comp[c->joint], c->comp[0], c->comp[1],
                     c->comp[2], w, sizeof(w)) < 0)
        return mot_reject(mot, "SET_JOINT_COMP: joint %d: %s", c->joint,
                          w[0] ? w : "refused");
    return MOT_ECHO_DONE;
}

/* SET_JOINT_MOTOR_OFFSET */
int mot_cmd_set_joint_motor_offset(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_joint(mot, c->joint)) ||
        (r = mot_bad_pos(mot, "motor offset", c->value)))
        return r;
    if (mot->joints[c->joint].free_tp.active)
        return mot_reject(mot, "SET_JOINT_MOTOR_OFFSET: joint %d is moving",
                          c->joint);
    mot->joints[c->joint].motor_offset = c->value;
    return MOT_ECHO_DONE;
}

/* SET_AXIS_POSITION_LIMITS */
int mot_cmd_set_axis_position_limits(mot_t *mot, const mot_command_t *c)
{
    int r;
    mot_axis_t *a;

    if ((r = mot_bad_axis(mot, c->axis)) || (r = mot_bad_limits(mot, c)))
        return r;
    a = &mot->axis[c->axis];
    a->min_pos_limit = c->min_limit;
    a->max_pos_limit = c->max_limit;
    return MOT_ECHO_DONE;
}

/* SET_AXIS_VEL_LIMIT */
int mot_cmd_set_axis_vel_limit(mot_t *mot, const mot_command_t *c)
{
    int r;
    mot_axis_t *a;

    if ((r = mot_bad_axis(mot, c->axis)) ||
        (r = mot_bad_positive(mot, "velocity", c->vel)))
        return r;
    a = &mot->axis[c->axis];
    a->vel_limit = c->vel;
    mot_axis_limits_to_planner(mot, c->axis);
    mot->tp->set_axis_limits(c->axis, a->vel_limit, a->acc_limit);
    return MOT_ECHO_DONE;
}

/* SET_AXIS_ACC_LIMIT */
int mot_cmd_set_axis_acc_limit(mot_t *mot, const mot_command_t *c)
{
    int r;
    mot_axis_t *a;

    if ((r = mot_bad_axis(mot, c->axis)) ||
        (r = mot_bad_positive(mot, "acceleration", c->acc)))
        return r;
    a = &mot->axis[c->axis];
    a->acc_limit = c->acc;
    mot_axis_limits_to_planner(mot, c->axis);
    mot->tp->set_axis_limits(c->axis, a->vel_limit, a->acc_limit);
    return MOT_ECHO_DONE;
}

/* SET_AXIS_JERK_LIMIT */
int mot_cmd_set_axis_jerk_limit(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_axis(mot, c->axis)) ||
        (r = mot_bad_nonneg(mot, "jerk", c->jerk)))
        return r;
    if (mot->axis[c->axis].tp.active)
        return mot_reject(mot, "SET_AXIS_JERK_LIMIT: axis %c is moving",
                          mot_axis_letters[c->axis]);
    mot->axis[c->axis].jerk_limit = c->jerk;
    if (c->jerk > 0)
        mot->profile = FP_JERK;
    mot_axis_limits_to_planner(mot, c->axis);
    return MOT_ECHO_DONE;
}

/* SET_PROFILE */
int mot_cmd_set_profile(mot_t *mot, const mot_command_t *c)
{
    int i;

    if (c->ival != FP_TRAPEZOID && c->ival != FP_JERK)
        return mot_reject(mot, "SET_PROFILE: %d is not a profile (0 "
                          "trapezoid, 1 jerk-limited)", c->ival);
    if (mot_moving(mot))
        return mot_reject(mot, "SET_PROFILE: cannot change the profile while "
                          "the machine moves");
    mot->profile = c->ival;
    for (i = 0; i < mot->num_joints; i++)
        mot_joint_limits_to_planner(mot, i);
    for (i = 0; i < MOT_MAX_AXES; i++)
        mot_axis_limits_to_planner(mot, i);
    return MOT_ECHO_DONE;
}

/* SET_LINEAR_UNITS */
int mot_cmd_set_linear_units(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_nonneg(mot, "millimetres per length unit", c->value)))
        return r;
    mot->linear_units = c->value;
    return MOT_ECHO_DONE;
}
