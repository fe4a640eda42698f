/*
 * tp.h - the interface between the motion module and a trajectory
 * planner module.
 *
 * The coordinated-mode planner is a separate, replaceable realtime module
 * (tpmod is the one shipped: blending look-ahead planner, see tpmod.c and
 * docs/motion.rst "How the planner blends").  It exports one table, the
 * symbol HALSDK_TP_SYMBOL, that motmod looks up when it loads.
 *
 * The planner works in Cartesian space: the nine axes of an EmcPose, in
 * machine units (user units per second for velocities).  It knows nothing
 * of joints or kinematics.  motmod calls every function from one thread
 * (the servo thread, its command handler, or at load time), so a planner
 * needs no locks.  The planner allocates its queue at load time
 * (hal_malloc); nothing here allocates.
 *
 * Functions that refuse something write a reason (a sentence with no
 * trailing period) into why[whylen] and return a negative errno; why may
 * be NULL.
 */
#ifndef HALSDK_TP_H
#define HALSDK_TP_H

#include "emcpose.h"

#define HALSDK_TP_SYMBOL "halsdk_tp_api"
#define HALSDK_TP_VERSION 2

/* Version 2 (issue 7) appended, never reordered: tp_move_t gained
   cam_tolerance and the spindle-synchronized fields, tp_inputs_t the feed
   controls and per-spindle inputs (used when the matching TP_IN_* bit is
   set in have, so a caller that zeroes the struct keeps v1 behaviour),
   tp_hooks_t the spindle hooks, tp_state_t more reports, and the table
   reset() and add_rigid_tap().  Every new struct field
   is zero-safe: a zeroed field means "not used". */
#define TP_MAX_SPINDLES 8

/* kinds of move (the numbers are those of the reference's motion types,
   shown on motion.motion-type) */
enum tp_motion_type {
    TP_MOTION_NONE = 0,         /* idle */
    TP_MOTION_TRAVERSE = 1,     /* rapid (G0): rapid scale applies */
    TP_MOTION_FEED = 2,         /* feed move (G1): feed scale applies */
    TP_MOTION_ARC = 3,          /* feed arc (G2/G3) */
    TP_MOTION_TOOLCHANGE = 4,
    TP_MOTION_PROBING = 5,      /* probe move (G38.n) */
    TP_MOTION_INDEXROTARY = 6
};

/* what happens at the end of a move */
enum tp_term_cond {
    TP_TERM_STOP = 0,           /* exact stop: come to rest (G61.1) */
    TP_TERM_EXACT = 1,          /* exact path, no stop needed (G61) */
    TP_TERM_BLEND = 2           /* blend within tolerance (G64 P) */
};

/* bits of tp_move_t.flags */
#define TP_MOVE_NO_FEED_SCALE   0x0001  /* overrides do not apply */
#define TP_MOVE_NO_FEED_HOLD    0x0002  /* feed hold does not apply */

/* bits of the probe type (add_probe) */
#define TP_PROBE_NO_ERROR       0x0001  /* no error if the move ends
                                           without contact (G38.3/.5) */
#define TP_PROBE_AWAY           0x0002  /* trip when the input goes false
                                           (G38.4/.5) */

/* kinds of spindle synchronization (tp_move_t.sync) */
enum tp_sync {
    TP_SYNC_NONE = 0,           /* ordinary move */
    TP_SYNC_POSITION = 1,       /* G33: distance = pitch x spindle revs
                                   since the start (waits for at-speed and
                                   the index before starting) */
    TP_SYNC_VELOCITY = 2        /* G95-like: path velocity = pitch x
                                   spindle speed (no index wait) */
};

/* what every queued move carries besides its geometry */
typedef struct {
    int id;                     /* motion id (from the command) */
    int type;                   /* enum tp_motion_type */
    double vel;                 /* requested path velocity, > 0 */
    double ini_maxvel;          /* path velocity never exceeded, overrides
                                   included, > 0 */
    double acc;                 /* path acceleration limit, > 0 */
    double jerk;                /* path jerk limit; 0: none */
    int term_cond;              /* enum tp_term_cond */
    double tolerance;           /* blend tolerance (G64 P): the largest
                                   distance of the path from the
                                   programmed one; 0: as fast as the
                                   limits allow */
    unsigned flags;             /* TP_MOVE_* */
    /* --- version 2 --- */
    double cam_tolerance;       /* G64 Q: consecutive lines whose
                                   vertices stay within this distance of
                                   the merged line are run as one line
                                   (term_cond TP_TERM_BLEND only); 0: no
                                   merging */
    int sync;                   /* enum tp_sync */
    int spindle;                /* the spindle a synchronized move
                                   follows, 0..TP_MAX_SPINDLES-1 */
    double pitch;               /* synchronized moves: path distance per
                                   spindle revolution (> 0) */
} tp_move_t;

/* one spindle's inputs (version 2) */
typedef struct {
    double revs;                /* spindle.N.revs */
    double speed;               /* spindle.N.speed-in, rev/s */
    int at_speed;               /* spindle.N.at-speed */
    int index_enable;           /* spindle.N.index-enable as read back:
                                   the planner arms it through the
                                   index_enable hook and waits for it to
                                   go false (the index was seen) */
} tp_spindle_in_t;

/* bits of tp_inputs_t.have: which version-2 fields the caller filled */
#define TP_IN_FEED      0x0001  /* feed_hold, feed_inhibit, adaptive_feed */
#define TP_IN_SPINDLES  0x0002  /* spindle[] */

/* inputs of one planner cycle (read from motmod's pins) */
typedef struct {
    int probe_input;            /* motion.probe-input */
    double spindle_revs;        /* spindle.0.revs (synchronized moves) */
    double spindle_speed;       /* spindle.0.speed-in, rev/s */
    int spindle_at_speed;       /* spindle.0.at-speed */
    /* --- version 2 --- */
    unsigned have;              /* TP_IN_* bits; 0: the v1 fields only
                                   (feed hold etc. folded into set_scale by
                                   the caller; spindle 0 from the fields
                                   above, no index handshake) */
    int feed_hold;              /* motion.feed-hold: feed moves stop along
                                   the path (not TP_MOVE_NO_FEED_HOLD
                                   ones, not rapids) */
    int feed_inhibit;           /* motion.feed-inhibit: every move stops
                                   along the path; a synchronized move
                                   does not start */
    double adaptive_feed;       /* motion.adaptive-feed: multiplies the
                                   feed scale; clamped to 0..1 */
    tp_spindle_in_t spindle[TP_MAX_SPINDLES];
} tp_inputs_t;

/* outputs the planner fires at the start of a move (synchronized I/O) */
typedef struct {
    void (*set_dout)(int index, int value);
    void (*set_aout)(int index, double value);
    /* --- version 2 (NULL: not available; G33 then starts without the
       index, rigid tapping is refused) --- */
    /* set spindle.N.index-enable true (the planner then waits for it to
       read back false in tp_inputs_t.spindle[N].index_enable) */
    void (*index_enable)(int spindle);
    /* rigid tapping: reverse = 1: turn spindle N the other way than
       commanded; 0: restore the commanded direction */
    void (*spindle_reverse)(int spindle, int reverse);
} tp_hooks_t;

/* what run_cycle reports besides the position */
typedef struct {
    double vel;                 /* path velocity now */
    double acc;                 /* path acceleration now */
    double dtg;                 /* distance to go in the current move */
    EmcPose dtg_pose;           /* per-axis distance to go in the move */
    EmcPose vel_pose;           /* per-axis velocity now */
    int exec_id;                /* id of the move running; when idle,
                                   of the last one that ran (0: none) */
    int motion_type;            /* enum tp_motion_type of that move */
    int queue_depth;            /* moves queued, the running one included */
    int done;                   /* no move queued or running and at rest */
    int paused;                 /* paused and at rest */
    int probing;                /* a probe move runs */
    /* --- version 2 --- */
    double requested_vel;       /* the path velocity the running move asks
                                   for now, overrides included */
    int active_moves;           /* moves the look-ahead is blending
                                   through now (the running one included;
                                   for motion.active-tc / tc.N) */
    int waiting;                /* 1: a synchronized move waits for the
                                   spindle at-speed, 2: for the index,
                                   0: not waiting */
    int spindle_sync;           /* a spindle-synchronized move runs */
    int rigid_tap_reversed;     /* the spindle_reverse hook is active */
    double feed_scale;          /* the effective feed scale now (feed
                                   scale x adaptive feed, 0 while held) */
} tp_state_t;

typedef struct {
    int version;                /* HALSDK_TP_VERSION */

    /* load time (from motmod's rtapi_app_main): comp_id is motmod's (a
       planner may create pins under it), traj_period the planner cycle
       in seconds; hooks may be NULL (then sync I/O is ignored) */
    int (*init)(int comp_id, double traj_period, const tp_hooks_t *hooks,
                char *why, int whylen);

    /* the path velocity limit of every move (the machine's max velocity);
       <= 0: none */
    void (*set_vel_limit)(double vel);

    /* per-axis limits (axis 0..8 = X..W): every move is planned so that
       no axis exceeds them; <= 0: none */
    void (*set_axis_limits)(int axis, double vel, double acc);

    /* where the planner is (on entering coord mode; idle only) */
    int (*set_pos)(const EmcPose *pos, char *why, int whylen);
    void (*get_pos)(EmcPose *pos);

    /* queue a move from the end of the last queued one (or the present
       position) */
    int (*add_line)(const EmcPose *end, const tp_move_t *move,
                    char *why, int whylen);
    /* circle/helix: center is on the axis of the arc, normal gives the
       plane and the direction (counterclockwise seen from the tip of
       normal); turn = extra full turns (0: less than one turn);
       the XYZ end point's distance from the axis may differ from the
       start's (a spiral); the other six axes move linearly */
    int (*add_circle)(const EmcPose *end, const PmCartesian *center,
                      const PmCartesian *normal, int turn,
                      const tp_move_t *move, char *why, int whylen);
    /* straight probe move toward end; probe_type: TP_PROBE_* */
    int (*add_probe)(const EmcPose *end, const tp_move_t *move,
                     int probe_type, char *why, int whylen);

    /* synchronized outputs: applied when the next queued move starts
       (or at once when start_now) */
    int (*set_dout)(int index, int value, int start_now);
    int (*set_aout)(int index, double value, int start_now);

    /* stop along the path within the acceleration limits and drop every
       queued move; done once at rest */
    void (*abort)(void);
    /* stop along the path within the limits; keep the queue */
    void (*pause)(void);
    void (*resume)(void);
    /* resume, and pause again at the end of the present move (or of the
       next one when between moves) */
    void (*step)(void);

    /* feed scale (feed moves and arcs) and rapid scale (traverses),
       >= 0; applied with the acceleration limits */
    void (*set_scale)(double feed, double rapid);

    /* one planner cycle: advance and write the new commanded position */
    void (*run_cycle)(const tp_inputs_t *in, EmcPose *pos);
    void (*get_state)(tp_state_t *st);

    int (*is_done)(void);
    int (*queue_depth)(void);
    int (*queue_space)(void);       /* moves that can still be queued */
    int (*exec_id)(void);
    double (*distance_to_go)(void);
    double (*current_vel)(void);

    /* probing: 1 when the last probe move tripped (pos set to where the
       input changed), -1 when it ended without contact, 0 otherwise */
    int (*probe_result)(EmcPose *pos);
    void (*clear_probe)(void);

    /* returns the last failure text ("" if none) and clears it: motmod
       reports it as a motion error (e.g. a probe move that ended without
       contact, or a probe already tripped when its move starts) */
    const char *(*take_error)(void);

    /* --- version 2 --- */
    /* drop every queued move and all motion at once (no deceleration:
       for motion being disabled): the planner is at rest where its last
       commanded position was, paused/step/abort flags and pending
       synchronized outputs cleared; probe result kept */
    void (*reset)(void);
    /* rigid tapping (G33.1): a line to end following spindle
       move->spindle with move->pitch per rev; at end the spindle is
       reversed (hook), the tool follows it back to the start, the
       direction is restored, and the tool returns exactly to the start */
    int (*add_rigid_tap)(const EmcPose *end, const tp_move_t *move,
                         char *why, int whylen);
} halsdk_tp_api_t;

#endif
