/*
 * mot_cmd.h - private to motmod's command handler: the handler type of
 * the dispatch table (mot_command.c) and the handlers, one file per
 * command group:
 *
 *   mot_command.c      mailbox, move queue, dispatch table, the argument
 *                      checks shared by the handlers
 *   mot_cmd_mode.c     ABORT, modes, ENABLE / DISABLE, amplifiers,
 *                      (DE)ACTIVATE_JOINT, OVERRIDE_LIMITS
 *   mot_cmd_jog.c      JOG_*, SET_TELEOP_VECTOR
 *   mot_cmd_home.c     HOME, UNHOME, SET_JOINT_HOMING_PARAMS
 *   mot_cmd_config.c   SET_NUM_JOINTS, SET_JOINT_*, SET_AXIS_*, joint
 *                      comp tables, SET_PROFILE, SET_LINEAR_UNITS
 *   mot_cmd_traj.c     coordinated moves, probe, PAUSE / RESUME / STEP,
 *                      overrides, feed controls, SET_VEL / _ACC, term
 *                      condition, tool offset, SET_DOUT / SET_AOUT
 *   mot_cmd_spindle.c  SPINDLE_*
 *
 * A handler returns MOT_ECHO_DONE or MOT_ECHO_ACCEPTED, or refuses with
 * mot_reject(), which writes the reason into mot->why and returns
 * MOT_ECHO_REJECTED.  Handlers run in the servo thread: no allocation,
 * no locks.
 */
#ifndef HALSDK_MOT_CMD_H
#define HALSDK_MOT_CMD_H

#include "mot_priv.h"

typedef int mot_cmd_fn(mot_t *mot, const mot_command_t *c);

/* ---- mot_command.c: names and argument checks (0 or the rejection) */
extern const char *const mot_mode_names[];     /* by enum mot_mode */
extern const char mot_axis_letters[];          /* "XYZABCUVW" */
int mot_reject(mot_t *mot, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
const char *mot_cmd_name(int c);
int mot_bad_joint(mot_t *mot, int j);
int mot_bad_axis(mot_t *mot, int a);
int mot_bad_pos(mot_t *mot, const char *what, double v);
int mot_bad_positive(mot_t *mot, const char *what, double v);
int mot_bad_nonneg(mot_t *mot, const char *what, double v);
int mot_bad_pose(mot_t *mot, const char *what, const EmcPose *p);
int mot_bad_cart(mot_t *mot, const char *what, const PmCartesian *c);
int mot_bad_spindle(mot_t *mot, int n);
int mot_bad_limits(mot_t *mot, const mot_command_t *c);
int mot_any_homing(mot_t *mot);

/* ---- mot_cmd_mode.c */
mot_cmd_fn mot_cmd_abort, mot_cmd_mode, mot_cmd_enable, mot_cmd_disable,
    mot_cmd_amplifier, mot_cmd_activate_joint, mot_cmd_deactivate_joint,
    mot_cmd_override_limits;

/* ---- mot_cmd_jog.c */
mot_cmd_fn mot_cmd_jog, mot_cmd_teleop_vector;

/* ---- mot_cmd_home.c */
mot_cmd_fn mot_cmd_home, mot_cmd_unhome, mot_cmd_set_joint_homing_params;

/* ---- mot_cmd_config.c */
mot_cmd_fn mot_cmd_set_num_joints, mot_cmd_set_joint_position_limits,
    mot_cmd_set_joint_vel_limit, mot_cmd_set_joint_acc_limit,
    mot_cmd_set_joint_jerk_limit, mot_cmd_set_joint_ferror,
    mot_cmd_set_joint_backlash, mot_cmd_joint_comp,
    mot_cmd_set_joint_motor_offset, mot_cmd_set_axis_position_limits,
    mot_cmd_set_axis_vel_limit, mot_cmd_set_axis_acc_limit,
    mot_cmd_set_axis_jerk_limit, mot_cmd_set_profile,
    mot_cmd_set_linear_units;

/* ---- mot_cmd_traj.c */
mot_cmd_fn mot_cmd_move, mot_cmd_clear_probe_flag, mot_cmd_pause,
    mot_cmd_resume, mot_cmd_step, mot_cmd_scale, mot_cmd_set_vel,
    mot_cmd_set_vel_limit, mot_cmd_set_acc, mot_cmd_set_term_cond,
    mot_cmd_set_offset, mot_cmd_set_dout, mot_cmd_set_aout,
    mot_cmd_feed_enables;
/* check a move's arguments and fill m (0 or the rejection): for a move
   that the mailbox holds until the spindle is at speed */
int mot_check_move(mot_t *mot, const mot_command_t *c, tp_move_t *m);

/* ---- mot_cmd_spindle.c */
mot_cmd_fn mot_cmd_spindle;

#endif
