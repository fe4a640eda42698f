/*
 * mot_joint.h - the realtime state of one joint, shared by the motion
 * module (motmod) and the homing module (homemod).
 *
 * motmod owns the array (allocated with hal_malloc at load time) and
 * hands its address to the homing module once, at load time.  Within a
 * servo cycle motmod first reads its input pins into the array, then lets
 * homing run (homing may move the joint's free planner and, when it
 * latches a home position, change motor_offset and shift pos_cmd, pos_fb
 * and the free planner by the same amount), then computes its outputs.
 * All positions are in joint units; all times in seconds.
 */
#ifndef HALSDK_MOT_JOINT_H
#define HALSDK_MOT_JOINT_H

#include "freeplan.h"

/* bits of mot_joint_t.flags */
#define MOT_JOINT_ACTIVE        0x0001  /* calculations on */
#define MOT_JOINT_ENABLED       0x0002  /* amp enabled */
#define MOT_JOINT_INPOS         0x0004  /* free planner at rest */
#define MOT_JOINT_ERROR         0x0008  /* a limit, ferror or fault */
#define MOT_JOINT_POS_SOFT      0x0010  /* at or past max_pos_limit */
#define MOT_JOINT_NEG_SOFT      0x0020  /* at or past min_pos_limit */
#define MOT_JOINT_POS_HARD      0x0040  /* pos-lim-sw-in true */
#define MOT_JOINT_NEG_HARD      0x0080  /* neg-lim-sw-in true */
#define MOT_JOINT_FERROR        0x0100  /* following error too big */
#define MOT_JOINT_FAULT         0x0200  /* amp-fault-in true */
#define MOT_JOINT_HOMING        0x0400  /* mirrors homing: is_homing */
#define MOT_JOINT_HOMED         0x0800  /* mirrors homing: is_homed */

typedef struct {
    int index;                  /* joint number */
    unsigned flags;             /* MOT_JOINT_* */

    /* configuration, from the SET_JOINT_* commands */
    double min_pos_limit;       /* soft limits, joint units */
    double max_pos_limit;
    double vel_limit;           /* units per second */
    double acc_limit;           /* units per second^2 */
    double jerk_limit;          /* units per second^3; 0: none */
    double min_ferror;          /* following error limit at rest */
    double max_ferror;          /* ... at vel_limit */
    double backlash;

    /* the seven positions, joint part (see docs/motion.rst) */
    double coarse_pos;          /* before interpolation (traj rate) */
    double pos_cmd;             /* after interpolation (servo rate) */
    double vel_cmd;
    double acc_cmd;
    double motor_offset;        /* set by homing */
    double backlash_corr;       /* raw backlash + screw correction */
    double backlash_filt;       /* the correction as applied */
    double backlash_vel;
    double motor_pos_cmd;       /* pos_cmd + backlash_filt + motor_offset */
    double motor_pos_fb;        /* input */
    double pos_fb;              /* motor_pos_fb - backlash_filt - motor_offset */
    double ferror;              /* pos_cmd - pos_fb */
    double ferror_limit;        /* the limit at the present speed */
    double ferror_high_mark;    /* largest |ferror| seen since enable */

    /* hard limit switch inputs as last read (homing looks at them) */
    int pos_limit_sw;
    int neg_limit_sw;

    /* the joint's free-mode planner: jogs and homing moves */
    freeplan_t free_tp;

    /* pins of motmod: for homing to read (never written by homing) */
    int kb_jog_active;
    int wheel_jog_active;
} mot_joint_t;

#endif
