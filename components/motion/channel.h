/*
 * channel.h - the command channel and status snapshot of the motion
 * module (motmod).
 *
 * motmod creates one named shared block, MOT_CHANNEL_NAME, that holds a
 * mot_channel_t.  Programs outside the realtime threads (the Python client
 * halsdk.motion, test programs, user interfaces) attach to it by name and
 * talk to the realtime side through it.  Everything in it is plain C with
 * fixed sizes (int32_t, uint32_t, uint64_t, double, char arrays and the
 * EmcPose of emcpose.h), so that a Cython or ctypes reader can mirror it.
 * Every double is 8-byte aligned; explicit pad fields keep the layout the
 * same for any compiler of the platform.
 *
 * ---------------------------------------------------------------------
 * Sending a command (client side)
 * ---------------------------------------------------------------------
 *  1. Take the client lock: compare-and-swap lock_pid from 0 to your pid.
 *     If it holds the pid of a process that no longer exists
 *     (kill(pid, 0) fails with ESRCH), the owner died while holding it:
 *     compare-and-swap it from that pid to yours.  Several processes may
 *     send commands; only the lock holder writes the command record.
 *  2. Wait until echo_seq == cmd_seq (the handler took the previous
 *     command; normally true at once).
 *  3. Fill in `command` (zero it first; unused fields stay zero).
 *  4. Release barrier (__atomic_thread_fence(__ATOMIC_RELEASE) or a
 *     store-release of cmd_seq), then write cmd_seq = cmd_seq + 1 (never
 *     0 after wrapping: skip 0).  The new value is the command's
 *     sequence number.
 *  5. Wait until echo_seq equals that number, then read echo_status and
 *     echo_reason (the handler writes both before it publishes echo_seq
 *     with a release store, so read echo_seq with acquire first).
 *  6. Release the lock: store 0 into lock_pid.
 *
 * The handler (function motion-command-handler, once per servo cycle)
 * compares cmd_seq with the last number it took; when they differ it
 * reads cmd_seq with acquire, copies the record, checks it and either
 * runs it or rejects it, then writes echo_status, echo_reason and finally
 * echo_seq = the number it took.  It takes at most one command per
 * cycle.  One exception: a feed move (SET_LINE / SET_CIRCLE of type feed
 * or arc, SPINDLE_SYNC_LINE, RIGID_TAP) that arrives while a spindle
 * start or speed change is pending is left in the mailbox, unanswered,
 * until the planner has run out and every turning spindle is at speed.
 *
 * echo_status:
 *  MOT_ECHO_DONE      the command has been carried out completely
 *                     (configuration, mode change, enable ...);
 *  MOT_ECHO_ACCEPTED  the command started something that goes on in
 *                     later cycles (a jog, a homing run, a queued move):
 *                     watch the status for its end (in_position,
 *                     joint flags, queue_depth, motion_id);
 *  MOT_ECHO_REJECTED  nothing was done; echo_reason says why in one
 *                     English sentence without a final period, e.g.
 *                     "joint 5 does not exist (num_joints=3)".
 * echo_reason is "" for DONE and ACCEPTED.
 *
 * ---------------------------------------------------------------------
 * Reading the status (seqlock)
 * ---------------------------------------------------------------------
 * The realtime side rewrites `status` every servo cycle:
 *     status_seq += 1 (now odd); release fence; write status;
 *     release fence; status_seq += 1 (even again).
 * A reader:
 *     do { s1 = status_seq (acquire); if (s1 & 1) retry;
 *          copy status; acquire fence; s2 = status_seq; }
 *     while (s1 != s2);
 * The copy is then one consistent snapshot of a single cycle.
 *
 * ---------------------------------------------------------------------
 * Error messages
 * ---------------------------------------------------------------------
 * Faults and failures detected by the realtime side (following error,
 * hard limits, amplifier faults, motion.enable going false, misc errors,
 * homing failures) are posted as text into a ring of MOT_MSG_RING
 * entries.  msg_count is the number of messages ever posted; message n
 * (0-based) lives in msgs[n % MOT_MSG_RING] and carries n in its `n`
 * field.  The writer fills the entry, then (release) increments
 * msg_count.  A reader remembers how many it has read (r); while
 * r < msg_count it copies msgs[r % MOT_MSG_RING] and accepts the copy if
 * its `n` is r and msg_count - r < MOT_MSG_RING still holds after the
 * copy (otherwise the message was overwritten: skip to
 * msg_count - MOT_MSG_RING + 1).  Messages are also printed with
 * rtapi_print_msg at the error level.
 *
 * ---------------------------------------------------------------------
 * Profiles of the free and teleop planners (SET_PROFILE)
 * ---------------------------------------------------------------------
 * Each joint (free mode) and each axis (teleop mode) has its own planner
 * (freeplan.h).  The machine-wide profile setting starts as
 * FP_TRAPEZOID.  SET_PROFILE with ival = FP_TRAPEZOID or FP_JERK changes
 * it; SET_JOINT_JERK_LIMIT or SET_AXIS_JERK_LIMIT with a value > 0 also
 * switches it to FP_JERK.  A planner runs jerk-limited when the setting
 * is FP_JERK and its own jerk limit is > 0; a coordinate with jerk
 * limit 0 always runs trapezoidal.  The setting is in status.profile.
 *
 * ---------------------------------------------------------------------
 * Modes and faults
 * ---------------------------------------------------------------------
 * FREE, TELEOP and COORD are rejected while anything moves or a joint
 * homes; TELEOP and COORD need all joints homed unless the kinematics are
 * identity.  HOME needs free mode, motion enabled, motion.homing-inhibit
 * false and the joint(s) at rest.  While motion is disabled the commanded
 * positions follow the feedback.  A fault (motion.enable false, an
 * amplifier fault, a hard limit, a following error above the limit
 * scaled linearly from min_ferror at rest to max_ferror at the joint's
 * velocity limit, a misc error) disables motion, turns the amplifiers
 * off, sets status.error and posts a message; ENABLE clears status.error.
 *
 * ---------------------------------------------------------------------
 * The move queue (ring of queued records)
 * ---------------------------------------------------------------------
 * The command mailbox takes one command per servo cycle and answers each
 * one; a part program needs several moves per cycle.  Moves and what must
 * keep its order with them go through a ring of MOT_QUEUE_SIZE command
 * records instead, with no answer per record:
 *     SET_LINE, SET_CIRCLE, PROBE, SPINDLE_SYNC_LINE, RIGID_TAP,
 *     SET_DOUT / SET_AOUT (sync 1: at the start of the next move; 0: when
 *     the handler takes the record), SET_TERM_COND, SET_VEL, SET_ACC,
 *     SET_VEL_LIMIT, SET_FEED_HOLD_ENABLE, SET_ADAPTIVE_FEED_ENABLE.
 * Other codes in the ring are rejected.  The same records are accepted
 * by the mailbox too (then answered one by one).
 *
 * q_head counts the records ever written (only the client writes it),
 * q_tail those the handler took (only the handler writes it); both wrap
 * at 2^32, the ring holds q_head - q_tail <= MOT_QUEUE_SIZE records and
 * record n lives in queue[n % MOT_QUEUE_SIZE].  The writer must hold the
 * client lock (one producer at a time).  Writing:
 *     wait until q_head - q_tail (acquire) < MOT_QUEUE_SIZE;
 *     fill queue[q_head % MOT_QUEUE_SIZE] with epoch = q_err_count as
 *     last read; release store q_head + 1.
 * Every servo cycle, after the mailbox, the handler takes records while
 * the planner has room for a move (up to MOT_QUEUE_BURST per cycle),
 * and publishes q_tail with a release store.  A record that is refused
 * stops the queue: the handler writes q_err_cmd, q_err_id, q_err_line
 * and q_err_reason, posts the reason as an error message, then
 * increments q_err_count (release).  From then on every record whose
 * epoch is not the new q_err_count is dropped unread (the rest of the
 * program that was already written); a client that sees q_err_count
 * change reports the error and writes new records with the new epoch.
 * ABORT and DISABLE (and every fault) drop the records not yet taken.
 * The moves the planner already has run on (ABORT stops them).
 *
 * ---------------------------------------------------------------------
 * Versioning
 * ---------------------------------------------------------------------
 * magic, version and size are written once by motmod before anything
 * else; a client must refuse a block whose magic or version differs from
 * its own or whose size is smaller than sizeof(mot_channel_t).
 */
#ifndef HALSDK_MOT_CHANNEL_H
#define HALSDK_MOT_CHANNEL_H

#include <stdint.h>
#include "emcpose.h"

#define MOT_CHANNEL_NAME    "motmod.channel"
#define MOT_CHANNEL_MAGIC   0x4d4f5443u     /* "MOTC" */
#define MOT_CHANNEL_VERSION 2

#define MOT_MAX_JOINTS      16
#define MOT_MAX_AXES        9       /* X Y Z A B C U V W */
#define MOT_MAX_SPINDLES    8
#define MOT_MAX_DIO         64
#define MOT_MAX_AIO         64
#define MOT_MAX_MISC_ERROR  64
#define MOT_REASON_LEN      200
#define MOT_MSG_LEN         200
#define MOT_MSG_RING        32
#define MOT_QUEUE_SIZE      1024    /* records of the move queue ring */
#define MOT_QUEUE_BURST     16      /* records taken per cycle, at most */

/* command codes (mot_command_t.cmd); the numbers are part of the
   protocol and never change */
enum mot_cmd {
    MOT_CMD_NONE = 0,

    /* state and modes */
    MOT_CMD_ABORT = 1,              /* stop all motion (any mode) */
    MOT_CMD_FREE = 2,               /* mode changes need all at rest */
    MOT_CMD_TELEOP = 3,
    MOT_CMD_COORD = 4,
    MOT_CMD_ENABLE = 5,
    MOT_CMD_DISABLE = 6,
    MOT_CMD_ENABLE_AMPLIFIER = 7,   /* joint: set joint.N.amp-enable-out */
    MOT_CMD_DISABLE_AMPLIFIER = 8,  /* joint */
    MOT_CMD_ACTIVATE_JOINT = 9,     /* joint */
    MOT_CMD_DEACTIVATE_JOINT = 10,  /* joint */
    MOT_CMD_PAUSE = 11,             /* coord planner */
    MOT_CMD_RESUME = 12,
    MOT_CMD_STEP = 13,              /* resume, pause again at the next
                                       move (id) */
    MOT_CMD_SCALE = 14,             /* feed scale: value >= 0 */
    MOT_CMD_RAPID_SCALE = 15,       /* rapid scale: value >= 0 */
    MOT_CMD_OVERRIDE_LIMITS = 16,   /* ival 1: hard limit switches do
                                       not trip until the jog that starts
                                       next has ended (to jog off a
                                       switch; jogs further onto it are
                                       rejected); ival 0: cancel */

    /* homing */
    MOT_CMD_HOME = 20,              /* joint, or -1: all with a sequence */
    MOT_CMD_UNHOME = 21,            /* joint, -1 all, -2 volatile ones */

    /* jogs: joint >= 0 in free mode (joint jog); joint = -1 and
       axis >= 0 in teleop mode (axis jog).  They need motion enabled,
       no joint homing and motion.jog-inhibit false; several joints (or
       axes) may jog at once.  A homed joint's targets are clamped to its
       soft limits (with all joints homed, an axis' to the axis limits),
       and a jog that would go further from a limit the coordinate is at
       is rejected.  Speeds above the limit are reduced to it; the feed
       scale applies.  JOG_INCR adds to the target of a JOG_INCR still
       running on the same joint (cumulative).  The echo is ACCEPTED;
       the jog ends when status joint[n].jog_active (axis[n].jog_active)
       goes 0. */
    MOT_CMD_JOG_CONT = 30,          /* vel signed: direction and speed */
    MOT_CMD_JOG_INCR = 31,          /* offset signed increment, vel > 0 */
    MOT_CMD_JOG_ABS = 32,           /* offset = target, vel > 0 */
    MOT_CMD_JOG_STOP = 33,          /* stop the jog of joint / axis */

    /* coordinated and teleop moves; SET_LINE, SET_CIRCLE and PROBE
       need coord mode and motion enabled; ini_maxvel 0 means the
       SET_VEL_LIMIT value, acc 0 the SET_ACC value; with all joints
       homed the end point must lie within the axis limits */
    MOT_CMD_SET_LINE = 40,          /* pos, id, motion_type, vel,
                                       ini_maxvel, acc, jerk (0: none),
                                       ival = TP_MOVE_* flags of tp.h */
    MOT_CMD_SET_CIRCLE = 41,        /* pos, center, normal, turn, id,
                                       motion_type, vel, ini_maxvel, acc */
    MOT_CMD_SET_TELEOP_VECTOR = 42, /* pos = velocity of each axis */
    MOT_CMD_PROBE = 43,             /* pos, id, vel, ini_maxvel, acc,
                                       ival = probe type bits */
    MOT_CMD_CLEAR_PROBE_FLAG = 44,

    /* configuration */
    MOT_CMD_SET_NUM_JOINTS = 50,    /* ival: 1..loaded num_joints */
    MOT_CMD_SET_JOINT_POSITION_LIMITS = 51, /* joint, min_limit,
                                               max_limit */
    MOT_CMD_SET_JOINT_VEL_LIMIT = 52,       /* joint, vel > 0 */
    MOT_CMD_SET_JOINT_ACC_LIMIT = 53,       /* joint, acc > 0 */
    MOT_CMD_SET_JOINT_JERK_LIMIT = 54,      /* joint, jerk >= 0 */
    MOT_CMD_SET_JOINT_MIN_FERROR = 55,      /* joint, value >= 0 */
    MOT_CMD_SET_JOINT_MAX_FERROR = 56,      /* joint, value >= 0 */
    MOT_CMD_SET_JOINT_HOMING_PARAMS = 57,   /* joint, home */
    MOT_CMD_SET_JOINT_BACKLASH = 58,        /* joint, value >= 0 */
    MOT_CMD_SET_JOINT_COMP = 59,    /* joint, comp[0..2] = nominal,
                                       forward, reverse: one entry of the
                                       joint's screw compensation table,
                                       nominal strictly increasing */
    MOT_CMD_CLEAR_JOINT_COMP = 60,  /* joint: empty its table */
    MOT_CMD_SET_JOINT_MOTOR_OFFSET = 61,    /* joint, value */
    MOT_CMD_SET_AXIS_POSITION_LIMITS = 62,  /* axis, min_limit, max_limit */
    MOT_CMD_SET_AXIS_VEL_LIMIT = 63,        /* axis, vel > 0 */
    MOT_CMD_SET_AXIS_ACC_LIMIT = 64,        /* axis, acc > 0 */
    MOT_CMD_SET_AXIS_JERK_LIMIT = 65,       /* axis, jerk >= 0 */
    MOT_CMD_SET_VEL = 66,           /* vel: requested velocity of coord
                                       moves; ini_maxvel */
    MOT_CMD_SET_VEL_LIMIT = 67,     /* vel: limit of all coord moves */
    MOT_CMD_SET_ACC = 68,           /* acc: acceleration of coord moves */
    MOT_CMD_SET_TERM_COND = 69,     /* ival = MOT_TERM_*, tolerance */
    MOT_CMD_SET_OFFSET = 70,        /* pos = tool offset */
    MOT_CMD_SET_PROFILE = 71,       /* ival = FP_TRAPEZOID / FP_JERK */
    MOT_CMD_SET_DOUT = 72,          /* index, ival 0/1: now */
    MOT_CMD_SET_AOUT = 73,          /* index, value: now */

    /* feed control and units */
    MOT_CMD_SET_FEED_HOLD_ENABLE = 100,     /* ival 1/0: motion.feed-hold
                                               applies (M53 P1) or not;
                                               default 1 */
    MOT_CMD_SET_ADAPTIVE_FEED_ENABLE = 101, /* ival 1/0: motion.adaptive-
                                               feed applies (M52 P1) or
                                               not; default 0 */
    MOT_CMD_SET_LINEAR_UNITS = 102,         /* value = millimetres per
                                               machine length unit (1 for
                                               mm, 25.4 for inch); 0:
                                               unknown */

    /* spindles: index = spindle number (0 .. num_spindles-1) */
    MOT_CMD_SPINDLE_ON = 110,       /* vel = speed in rpm, the sign gives
                                       the direction (> 0 forward);
                                       optional CSS: value = surface speed
                                       (units/min) > 0, ival = the axis
                                       the radius is measured on (0 X),
                                       offset = the maximum rpm */
    MOT_CMD_SPINDLE_OFF = 111,
    MOT_CMD_SPINDLE_INCREASE = 112, /* value = rpm step (0: 10 %) */
    MOT_CMD_SPINDLE_DECREASE = 113,
    MOT_CMD_SPINDLE_ORIENT = 114,   /* value = angle (degrees), ival =
                                       mode (orient-mode pin) */
    MOT_CMD_SPINDLE_BRAKE_ENGAGE = 115,
    MOT_CMD_SPINDLE_BRAKE_RELEASE = 116,

    /* spindle-synchronized moves (queued like SET_LINE; they need the
       spindle on): pos, id, vel (the velocity limit of the move),
       ini_maxvel, acc, pitch = travel per revolution (> 0), index =
       spindle */
    MOT_CMD_SPINDLE_SYNC_LINE = 120,    /* G33: a threading move */
    MOT_CMD_RIGID_TAP = 121,            /* G33.1: in to pos, reverse the
                                           spindle, out to the start */

    /* 122..149: reserved */
    MOT_CMD_RESERVED_FIRST = 122,
    MOT_CMD_RESERVED_LAST = 149,

    MOT_CMD_LAST = 150              /* all codes are < this */
};

/* echo_status */
enum mot_echo {
    MOT_ECHO_NONE = 0,              /* no command yet */
    MOT_ECHO_DONE = 1,
    MOT_ECHO_ACCEPTED = 2,
    MOT_ECHO_REJECTED = 3
};

/* status.mode */
enum mot_mode {
    MOT_MODE_FREE = 0,
    MOT_MODE_TELEOP = 1,
    MOT_MODE_COORD = 2
};

/* SET_TERM_COND ival (same numbers as tp.h enum tp_term_cond) */
enum mot_term {
    MOT_TERM_STOP = 0,              /* exact stop at the end of each move */
    MOT_TERM_EXACT = 1,             /* exact path */
    MOT_TERM_BLEND = 2              /* blend within tolerance */
};

/* motion_type of SET_LINE / SET_CIRCLE and of pin motion.motion-type
   (the reference's numbers) */
enum mot_motion_type {
    MOT_MOTION_NONE = 0,
    MOT_MOTION_TRAVERSE = 1,
    MOT_MOTION_FEED = 2,
    MOT_MOTION_ARC = 3,
    MOT_MOTION_TOOLCHANGE = 4,
    MOT_MOTION_PROBING = 5,
    MOT_MOTION_INDEXROTARY = 6
};

/* status.kins_type: kinematicsType() of kins(9) */
enum mot_kins_type {
    MOT_KINS_IDENTITY = 1,
    MOT_KINS_FORWARD_ONLY = 2,
    MOT_KINS_INVERSE_ONLY = 3,
    MOT_KINS_BOTH = 4
};

/* PROBE ival bits (same as tp.h TP_PROBE_*) */
#define MOT_PROBE_NO_ERROR      0x1     /* no error if not tripped */
#define MOT_PROBE_AWAY          0x2     /* trip when the input goes false */

/* the command record */
typedef struct {
    int32_t cmd;                /* enum mot_cmd */
    int32_t joint;              /* joint number; -1: none / all */
    int32_t axis;               /* axis number 0=X .. 8=W; -1: none */
    int32_t ival;               /* integer argument (see the codes) */
    int32_t index;              /* SET_DOUT / SET_AOUT: output number;
                                   spindle number (issue 7) */
    int32_t id;                 /* motion id of SET_LINE / SET_CIRCLE /
                                   PROBE (shown as status.motion_id) */
    int32_t motion_type;        /* enum mot_motion_type */
    int32_t turn;               /* SET_CIRCLE: extra full turns */
    double vel;                 /* velocity argument */
    double ini_maxvel;          /* velocity limit of the move */
    double acc;                 /* acceleration argument */
    double jerk;                /* jerk argument */
    double offset;              /* JOG_INCR increment, JOG_ABS target */
    double value;               /* scale, ferror, backlash, offset, aout */
    double min_limit;           /* SET_*_POSITION_LIMITS */
    double max_limit;
    double tolerance;           /* SET_TERM_COND */
    double comp[3];             /* SET_JOINT_COMP: nominal, forward,
                                   reverse */
    EmcPose pos;                /* end point / velocity vector / offset */
    PmCartesian center;         /* SET_CIRCLE */
    PmCartesian normal;
    /* SET_JOINT_HOMING_PARAMS (see homing.h mot_home_params_t) */
    double home_offset;
    double home;
    double home_search_vel;
    double home_latch_vel;
    double home_final_vel;
    int32_t home_sequence;
    int32_t volatile_home;
    uint32_t home_flags;        /* HOME_* of homing.h */
    int32_t pad0;
    int32_t line;               /* program line of a move (shown on
                                   motion.program-line while it runs) */
    uint32_t epoch;             /* queued records: the queue's error
                                   count q_err_count the client had seen
                                   when it wrote the record */
    int32_t sync;               /* SET_DOUT / SET_AOUT: 0 now, 1 when the
                                   next queued move starts */
    int32_t pad1;
    double pitch;               /* spindle-synchronized moves: travel per
                                   spindle revolution */
    double reserved[5];         /* zero */
} mot_command_t;

/* one joint in the status snapshot */
typedef struct {
    uint32_t flags;             /* MOT_JOINT_* of mot_joint.h */
    int32_t home_state;         /* joint.N.home-state */
    double pos_cmd;
    double pos_fb;
    double vel_cmd;
    double acc_cmd;
    double ferror;
    double ferror_limit;        /* at the present speed */
    double ferror_high_mark;
    double motor_offset;
    double motor_pos_cmd;
    double motor_pos_fb;
    double backlash_filt;       /* backlash + screw correction applied */
    double min_pos_limit;
    double max_pos_limit;
    double vel_limit;
    double acc_limit;
    double jerk_limit;
    double min_ferror;
    double max_ferror;
    double backlash;
    double free_target;         /* the free planner's target */
    int32_t free_active;        /* the free planner moves */
    int32_t jog_active;         /* a jog command moves the joint */
} mot_joint_status_t;

/* one axis (X .. W) */
typedef struct {
    double pos_cmd;             /* axis.L.pos-cmd */
    double vel_cmd;
    double teleop_pos;          /* teleop planner position */
    double teleop_vel;          /* teleop planner velocity */
    double teleop_target;
    double min_pos_limit;
    double max_pos_limit;
    double vel_limit;
    double acc_limit;
    double jerk_limit;
    int32_t teleop_active;      /* the teleop planner moves */
    int32_t jog_active;
} mot_axis_status_t;

/* one spindle */
typedef struct {
    double speed;               /* commanded speed, rpm, signed
                                   (spindle.N.speed-out) */
    double speed_in;            /* spindle.N.speed-in, rev/s */
    double revs;                /* spindle.N.revs */
    double orient_angle;
    double css_factor;          /* CSS surface speed, 0: off */
    int32_t on;                 /* spindle.N.on */
    int32_t direction;          /* 1 forward, -1 reverse, 0 off */
    int32_t brake;
    int32_t locked;             /* oriented and held */
    int32_t orient_state;       /* enum mot_orient_state */
    int32_t orient_fault;       /* last orient-fault code seen */
    int32_t at_speed;
    int32_t inhibit;
    int32_t amp_fault;
    int32_t pad0;
} mot_spindle_status_t;

/* mot_spindle_status_t.orient_state */
enum mot_orient_state {
    MOT_ORIENT_NONE = 0,
    MOT_ORIENT_RUNNING = 1,     /* spindle.N.orient true, waiting for
                                   is-oriented */
    MOT_ORIENT_DONE = 2,        /* is-oriented came: locked, brake on */
    MOT_ORIENT_FAULT = 3        /* orient-fault was not 0 */
};

typedef struct {
    uint64_t heartbeat;         /* servo cycles run by motion-controller */
    int32_t mode;               /* enum mot_mode */
    int32_t enabled;            /* motion enabled */
    int32_t in_position;        /* nothing moves */
    int32_t on_soft_limit;
    int32_t override_limits;    /* an OVERRIDE_LIMITS is in force */
    int32_t num_joints;         /* in use (SET_NUM_JOINTS) */
    int32_t num_joints_loaded;  /* modparam num_joints */
    int32_t num_extrajoints;
    int32_t kins_type;          /* enum mot_kins_type */
    int32_t homing;             /* a joint is homing */
    int32_t all_homed;
    int32_t paused;
    int32_t probing;
    int32_t probe_tripped;
    int32_t queue_depth;        /* coord moves queued (incl. current) */
    int32_t motion_id;          /* id of the coord move in progress */
    int32_t motion_type;        /* enum mot_motion_type */
    int32_t profile;            /* enum fp_profile setting */
    int32_t coord_error;
    int32_t error;              /* a fault disabled motion since the
                                   last ENABLE */
    int32_t num_dio;
    int32_t num_aio;
    int32_t num_spindles;
    int32_t term_cond;
    double feed_scale;
    double rapid_scale;
    double current_vel;
    double distance_to_go;
    double requested_vel;       /* SET_VEL */
    double vel_limit;           /* SET_VEL_LIMIT */
    double acc_limit;           /* SET_ACC */
    double tolerance;
    double servo_period;        /* seconds */
    double traj_period;
    EmcPose carte_pos_cmd;
    EmcPose carte_pos_fb;
    int32_t carte_pos_fb_ok;    /* carte_pos_fb is valid (forward kins
                                   ran on homed joints) */
    int32_t pad0;
    EmcPose probed_pos;
    EmcPose tool_offset;
    uint64_t dout;              /* motion.digital-out-NN bits */
    uint64_t din;               /* motion.digital-in-NN bits */
    mot_joint_status_t joint[MOT_MAX_JOINTS];
    mot_axis_status_t axis[MOT_MAX_AXES];
    /* issue 7 */
    int32_t program_line;       /* motion.program-line */
    int32_t feed_hold_enabled;  /* SET_FEED_HOLD_ENABLE */
    int32_t adaptive_enabled;   /* SET_ADAPTIVE_FEED_ENABLE */
    int32_t feed_hold;          /* motion.feed-hold is in force */
    int32_t feed_inhibit;       /* motion.feed-inhibit */
    int32_t queue_taken;        /* q_tail: queued records taken */
    uint32_t queue_err_count;   /* q_err_count */
    int32_t pad1;
    double adaptive_feed;       /* motion.adaptive-feed */
    double feed_upm;            /* motion.feed-upm */
    double linear_units;        /* mm per length unit (0: unknown) */
    double ain[MOT_MAX_AIO];    /* motion.analog-in-NN (num_aio used) */
    double aout[MOT_MAX_AIO];   /* motion.analog-out-NN */
    mot_spindle_status_t spindle[MOT_MAX_SPINDLES];
    int32_t spindle_wait;       /* the planner waits for a spindle: 1
                                   at-speed, 2 the index (tp_state_t
                                   waiting) */
    int32_t queue_held;         /* motmod holds the next feed move until
                                   the spindles are at speed */
    double reserved[15];        /* zero */
} mot_status_t;

typedef struct {
    uint64_t n;                 /* message number */
    char text[MOT_MSG_LEN];
} mot_msg_t;

typedef struct {
    uint32_t magic;             /* MOT_CHANNEL_MAGIC */
    uint32_t version;           /* MOT_CHANNEL_VERSION */
    uint32_t size;              /* sizeof(mot_channel_t) */
    int32_t lock_pid;           /* client lock: 0 free, else owner pid */

    /* command: client -> handler */
    volatile uint32_t cmd_seq;
    /* echo: handler -> client */
    volatile uint32_t echo_seq;
    volatile int32_t echo_status;   /* enum mot_echo */
    int32_t echo_cmd;               /* code of the command echoed */
    char echo_reason[MOT_REASON_LEN];
    mot_command_t command;

    /* status: realtime -> everyone (seqlock) */
    volatile uint32_t status_seq;
    int32_t pad0;
    mot_status_t status;

    /* error messages: realtime -> everyone */
    volatile uint64_t msg_count;
    mot_msg_t msgs[MOT_MSG_RING];

    /* the move queue ring: client -> handler (see "The move queue") */
    volatile uint32_t q_head;       /* records ever written (client) */
    volatile uint32_t q_tail;       /* records ever taken (handler) */
    volatile uint32_t q_err_count;  /* queued records rejected so far */
    int32_t q_err_cmd;              /* the last rejected record: code, */
    int32_t q_err_id;               /* id, */
    int32_t q_err_line;             /* line */
    char q_err_reason[MOT_REASON_LEN];  /* and why */
    mot_command_t queue[MOT_QUEUE_SIZE];
} mot_channel_t;

#endif
