/*
 * mot_priv.h - private state of the motion module (motmod), shared by
 * motmod.c (loading, pins), mot_command.c (command handler) and
 * mot_control.c (the servo-cycle controller).
 *
 * Everything lives in one mot_t that rtapi_app_main allocates with
 * hal_malloc; the realtime functions only read and write it, never
 * allocate.
 */
#ifndef HALSDK_MOT_PRIV_H
#define HALSDK_MOT_PRIV_H

#include "rtapi.h"
#include "hal.h"
#include "emcpose.h"
#include "freeplan.h"
#include "mot_joint.h"
#include "homing.h"
#include "tp.h"
#include "channel.h"

/* ---- kinematics: the functions of kins(9), found by name at load ---- */
#include "kinematics.h"
typedef int (*mot_kins_fwd_fn)(const double *joints, EmcPose *pos,
                               const KINEMATICS_FORWARD_FLAGS *fflags,
                               KINEMATICS_INVERSE_FLAGS *iflags);
typedef int (*mot_kins_inv_fn)(const EmcPose *pos, double *joints,
                               const KINEMATICS_INVERSE_FLAGS *iflags,
                               KINEMATICS_FORWARD_FLAGS *fflags);
typedef KINEMATICS_TYPE (*mot_kins_type_fn)(void);
typedef int (*mot_kins_switchable_fn)(void);
typedef int (*mot_kins_switch_fn)(int type);
typedef int (*mot_kins_home_fn)(EmcPose *pos, double *joints,
                                KINEMATICS_FORWARD_FLAGS *fflags,
                                KINEMATICS_INVERSE_FLAGS *iflags);

/* ---- backlash and screw compensation (H4's mot_comp.h) ---- */
#include "mot_comp.h"

/* a "far away" target for continuous jogs of a joint that has no soft
   limits yet (not homed): the planner never gets there */
#define MOT_FAR 1.0e9

/* ---- pins ---- */
typedef struct {
    hal_float_t *acc_cmd;
    hal_bit_t *active;
    hal_bit_t *amp_enable_out;
    hal_bit_t *amp_fault_in;
    hal_float_t *backlash_corr;
    hal_float_t *backlash_filt;
    hal_float_t *backlash_vel;
    hal_float_t *coarse_pos_cmd;
    hal_bit_t *error;
    hal_float_t *f_error;
    hal_float_t *f_error_lim;
    hal_bit_t *f_errored;
    hal_bit_t *faulted;
    hal_float_t *free_pos_cmd;
    hal_bit_t *free_tp_enable;
    hal_float_t *free_vel_lim;
    hal_bit_t *in_position;
    hal_float_t *jog_accel_fraction;
    hal_s32_t *jog_counts;
    hal_bit_t *jog_enable;
    hal_float_t *jog_scale;
    hal_bit_t *jog_vel_mode;
    hal_bit_t *kb_jog_active;
    hal_float_t *motor_offset;
    hal_float_t *motor_pos_cmd;
    hal_float_t *motor_pos_fb;
    hal_bit_t *neg_hard_limit;
    hal_bit_t *neg_lim_sw_in;
    hal_float_t *pos_cmd;
    hal_float_t *pos_fb;
    hal_bit_t *pos_hard_limit;
    hal_bit_t *pos_lim_sw_in;
    hal_float_t *vel_cmd;
    hal_bit_t *wheel_jog_active;
    hal_bit_t *unlock;              /* unlock_joints_mask joints only */
    hal_bit_t *is_unlocked;
    hal_float_t *posthome_cmd;      /* extra joints only */
} mot_joint_pins_t;

typedef struct {
    hal_float_t *eoffset;
    hal_bit_t *eoffset_clear;
    hal_s32_t *eoffset_counts;
    hal_bit_t *eoffset_enable;
    hal_float_t *eoffset_request;
    hal_float_t *eoffset_scale;
    hal_float_t *jog_accel_fraction;
    hal_s32_t *jog_counts;
    hal_bit_t *jog_enable;
    hal_float_t *jog_scale;
    hal_bit_t *jog_vel_mode;
    hal_bit_t *kb_jog_active;
    hal_float_t *pos_cmd;
    hal_float_t *teleop_pos_cmd;
    hal_bit_t *teleop_tp_enable;
    hal_float_t *teleop_vel_cmd;
    hal_float_t *teleop_vel_lim;
    hal_bit_t *wheel_jog_active;
} mot_axis_pins_t;

typedef struct {
    hal_bit_t *amp_fault_in;
    hal_bit_t *at_speed;
    hal_bit_t *brake;
    hal_bit_t *forward;
    hal_bit_t *index_enable;
    hal_bit_t *inhibit;
    hal_bit_t *is_oriented;
    hal_bit_t *locked;
    hal_bit_t *on;
    hal_bit_t *orient;
    hal_float_t *orient_angle;
    hal_s32_t *orient_fault;
    hal_s32_t *orient_mode;
    hal_bit_t *reverse;
    hal_float_t *revs;
    hal_float_t *speed_cmd_rps;
    hal_float_t *speed_in;
    hal_float_t *speed_out;
    hal_float_t *speed_out_abs;
    hal_float_t *speed_out_rps;
    hal_float_t *speed_out_rps_abs;
} mot_spindle_pins_t;

typedef struct {
    hal_float_t *adaptive_feed;
    hal_bit_t *coord_error;
    hal_bit_t *coord_mode;
    hal_float_t *current_vel;
    hal_float_t *distance_to_go;
    hal_bit_t *enable;
    hal_bit_t *eoffset_active;
    hal_bit_t *eoffset_limited;
    hal_bit_t *feed_hold;
    hal_float_t *feed_inches_per_minute;
    hal_float_t *feed_inches_per_second;
    hal_bit_t *feed_inhibit;
    hal_float_t *feed_mm_per_minute;
    hal_float_t *feed_mm_per_second;
    hal_float_t *feed_upm;
    hal_bit_t *homing_inhibit;
    hal_bit_t *in_position;
    hal_bit_t *is_all_homed;
    hal_bit_t *jog_inhibit;
    hal_bit_t *jog_is_active;
    hal_bit_t *jog_stop;
    hal_bit_t *jog_stop_immediate;
    hal_bit_t *motion_enabled;
    hal_s32_t *motion_type;
    hal_bit_t *on_soft_limit;
    hal_bit_t *probe_input;
    hal_s32_t *program_line;
    hal_float_t *requested_vel;
    hal_u32_t *servo_last_period;
    hal_bit_t *teleop_mode;
    hal_float_t *tooloffset[MOT_MAX_AXES];
    hal_bit_t *tp_reverse;
    hal_bit_t *digital_in[MOT_MAX_DIO];
    hal_bit_t *digital_out[MOT_MAX_DIO];
    hal_float_t *analog_in[MOT_MAX_AIO];
    hal_float_t *analog_out[MOT_MAX_AIO];
    hal_bit_t *misc_error[MOT_MAX_MISC_ERROR];
} mot_motion_pins_t;

typedef struct {
    hal_bit_t debug_bit[2];
    hal_float_t debug_float[4];
    hal_s32_t debug_s32[2];
    hal_float_t tc_acc[4], tc_pos[4], tc_vel[4];
    hal_u32_t active_tc;
    hal_float_t pos_out;
    hal_float_t vel_out;
} mot_params_t;

/* what started a joint's free planner: decides the end of a jog (for
   OVERRIDE_LIMITS) and whether JOG_INCR adds to the target */
enum mot_jog_kind {
    MOT_JOG_NONE = 0,
    MOT_JOG_CONT,
    MOT_JOG_INCR,
    MOT_JOG_ABS,
    MOT_JOG_WHEEL
};

/* one spindle's state (pins are in mot_spindle_pins_t) */
typedef struct {
    double speed;               /* commanded rpm, signed; 0: off */
    double css_factor;          /* CSS surface speed (units/min), 0: off */
    int css_axis;               /* axis the radius is measured on */
    double css_max;             /* CSS rpm limit (0: none) */
    int on;
    int brake;                  /* braked by BRAKE_ENGAGE or orient */
    int orient_state;           /* enum mot_orient_state */
    double orient_angle;
    int orient_mode;
    int orient_fault;
    int amp_fault;              /* latched until the next SPINDLE_ON */
    int index_armed;            /* motmod armed index-enable for G33 */
    int reversed;               /* rigid tap: turning the other way */
} mot_spindle_t;

/* one axis (X..W) in teleop mode */
typedef struct {
    freeplan_t tp;              /* teleop planner */
    double min_pos_limit, max_pos_limit;
    double vel_limit, acc_limit, jerk_limit;
    double pos_cmd, vel_cmd;
    int jog;                    /* enum mot_jog_kind, 0: vector or idle */
    double req_vel;             /* commanded speed (> 0) */
    int old_counts;
    int wheel_seen;
} mot_axis_t;

typedef struct {
    /* configuration (modparams) */
    int num_joints;             /* loaded */
    int num_joints_used;        /* SET_NUM_JOINTS */
    int num_extra;
    int num_dio, num_aio, num_misc, num_spindles;
    unsigned unlock_mask;
    double servo_period;        /* seconds */
    double traj_period;
    int interp_rate;            /* servo cycles per planner cycle */
    int comp_id;

    /* the modules found at load */
    const mot_homing_api_t *home;
    const halsdk_tp_api_t *tp;
    mot_kins_fwd_fn kins_fwd;
    mot_kins_inv_fn kins_inv;
    mot_kins_type_fn kins_type_fn;
    mot_kins_switchable_fn kins_switchable;
    mot_kins_switch_fn kins_switch;
    mot_kins_home_fn kins_home;
    int kins_type;

    /* the shared channel */
    long long chan_handle;
    mot_channel_t *chan;
    uint32_t last_seq;          /* last command sequence taken */
    char *why;                  /* where a command handler writes why it
                                   refuses (the echo's reason, or a
                                   buffer of the queue) */
    int whylen;

    /* state */
    int mode;                   /* enum mot_mode */
    int enabled;
    int error;                  /* a fault disabled motion */
    int override_limits;        /* OVERRIDE_LIMITS in force */
    int override_jog;           /* joint (>= 0) / axis (100 + n) whose
                                   jog ends the override; -1: none yet */
    int profile;                /* FP_TRAPEZOID / FP_JERK */
    double feed_scale, rapid_scale;
    double tp_feed, tp_rapid;   /* the scales the planner has now */
    double req_vel, vel_limit, acc_limit, tolerance;
    int term_cond;
    int traj_count;             /* servo cycles since the last tp cycle */
    EmcPose coarse_prev, coarse_next;   /* tp output, for interpolation */
    EmcPose carte_pos_cmd, carte_pos_fb;
    int carte_fb_ok;
    EmcPose tool_offset;
    EmcPose probed_pos;
    int probe_tripped;
    int tp_done, tp_paused, tp_probing, queue_depth, motion_id;
    int motion_type;
    double current_vel, distance_to_go;
    uint64_t heartbeat;
    int enable_pin_old;
    int inpos;
    uint64_t dout_bits;

    /* issue 7: feed control, the move queue, spindles */
    int feed_hold_enabled;      /* SET_FEED_HOLD_ENABLE (default 1) */
    int adaptive_enabled;       /* SET_ADAPTIVE_FEED_ENABLE (default 0) */
    int feed_hold_now, feed_inhibit_now;    /* in force this cycle */
    double adaptive_now;        /* factor applied this cycle */
    double linear_units;        /* mm per length unit; 0: unknown */
    double move_req_vel;        /* requested vel of the running move */
    double feed_upm;            /* motion.feed-upm */
    double cam_tolerance;       /* SET_TERM_COND value (G64 Q) */
    /* the moves given to the planner, oldest first: their id, program
       line and requested velocity, for motion.program-line and
       motion.requested-vel while they run */
    struct mot_line { int id, line; double vel; } *lines;
    int line_head, line_count;
    int program_line;
    int tp_spindle_wait;        /* the planner waits for the spindle */
    int wait_at_speed;          /* a spindle started or changed speed:
                                   the next feed move waits */
    mot_command_t deferred;     /* a feed move from the mailbox that waits
                                   for at-speed: answered at once, handed
                                   to the planner when the wait is over */
    int deferred_valid;
    mot_spindle_t spindle[MOT_MAX_SPINDLES];

    mot_joint_t *joints;        /* num_joints */
    mot_comp_t *comp;           /* num_joints: backlash and screw comp */
    int home_seq[MOT_MAX_JOINTS];       /* HOME_SEQUENCE of each joint */
    /* the homing module's answers, read once per servo cycle (after its
       run) so that the controller calls it only once per joint */
    unsigned char homed_c[MOT_MAX_JOINTS], homing_c[MOT_MAX_JOINTS];
    int all_homed_c;            /* joints in use all homed */
    int all_homed_api_c;        /* homing's all_homed() (extra joints too) */
    int any_homing_c;
    int jog_kind[MOT_MAX_JOINTS];
    double jog_vel[MOT_MAX_JOINTS];     /* requested jog speed */
    int old_counts[MOT_MAX_JOINTS];
    int wheel_seen[MOT_MAX_JOINTS];
    int amp_on[MOT_MAX_JOINTS];         /* ENABLE/DISABLE_AMPLIFIER */
    mot_axis_t axis[MOT_MAX_AXES];

    mot_joint_pins_t *jp;
    mot_axis_pins_t *ap;
    mot_spindle_pins_t *sp;
    mot_motion_pins_t *mp;
    mot_params_t *par;
} mot_t;

/*
 * The state is passed explicitly: every function below takes the mot_t
 * it works on.  The two HAL functions get it as their arg (hal_export_funct
 * is given the mot_t); only motmod.c keeps a pointer of its own, for
 * loading and unloading and for the planner hooks (tp_hooks_t), whose
 * signatures carry no context.
 */

/* mot_command.c: the HAL function motion-command-handler (arg: mot_t) */
void mot_command_handler(void *arg, long period);
/* mot_cmd_queue.c: drop the queued records not taken yet (ABORT,
   DISABLE, faults) */
void mot_queue_drop(mot_t *mot);
/* mot_cmd_spindle.c: spindles off and released (DISABLE, faults) */
void mot_spindles_stop(mot_t *mot);

#define MOT_LINE_FIFO 8192     /* moves remembered (>= the planner queue) */

/* mot_control.c: the HAL function motion-controller (arg: mot_t) */
void mot_controller(void *arg, long period);
void mot_line_push(mot_t *mot, int id, int line, double vel);
void mot_line_clear(mot_t *mot);
/* write the status snapshot of the channel (seqlock) */
void mot_write_status(mot_t *mot);
/* post an error message into the channel ring (and print it) */
void mot_post(mot_t *mot, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* stop everything: DISABLE and the faults */
void mot_disable(mot_t *mot);
/* put the planners of the current mode at the present positions */
void mot_sync_planners(mot_t *mot);
/* planner profile and limits of joint / axis from the configuration */
void mot_joint_limits_to_planner(mot_t *mot, int j);
void mot_axis_limits_to_planner(mot_t *mot, int a);
int mot_all_homed(mot_t *mot);
int mot_moving(mot_t *mot);     /* anything moves (not in position) */
/* forward/inverse kinematics over the joints in use */
int mot_forward(mot_t *mot, const double *joints, EmcPose *pos);
int mot_inverse(mot_t *mot, const EmcPose *pos, double *joints);

#endif
