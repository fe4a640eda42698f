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
#include "mot_cmd.h"

const char *const mot_mode_names[] = { "free", "teleop", "coord" };
const char mot_axis_letters[] = "XYZABCUVW";

/* refuse the command being run: the reason goes to mot->why */
int mot_reject(mot_t *mot, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(mot->why, mot->whylen, fmt, ap);
    va_end(ap);
    return MOT_ECHO_REJECTED;
}

const char *mot_cmd_name(int c)
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
int mot_bad_joint(mot_t *mot, int j)
{
    if (j < 0 || j >= mot->num_joints_used)
        return mot_reject(mot, "joint %d does not exist (num_joints=%d)", j,
                          mot->num_joints_used);
    return 0;
}

int mot_bad_axis(mot_t *mot, int a)
{
    if (a < 0 || a >= MOT_MAX_AXES)
        return mot_reject(mot, "axis %d does not exist (axes are 0..8 for "
                          "X..W)", a);
    return 0;
}

int mot_bad_pos(mot_t *mot, const char *what, double v)
{
    if (!isfinite(v))
        return mot_reject(mot, "%s must be a finite number, got %g", what, v);
    return 0;
}

int mot_bad_positive(mot_t *mot, const char *what, double v)
{
    if (!isfinite(v) || v <= 0)
        return mot_reject(mot, "%s must be a positive number, got %g", what,
                          v);
    return 0;
}

int mot_bad_nonneg(mot_t *mot, const char *what, double v)
{
    if (!isfinite(v) || v < 0)
        return mot_reject(mot, "%s must be zero or a positive number, got %g",
                          what, v);
    return 0;
}

int mot_bad_pose(mot_t *mot, const char *what, const EmcPose *p)
{
    int i;
    for (i = 0; i < MOT_MAX_AXES; i++) {
        double v = *emcpose_axis((EmcPose *)p, i);
        if (!isfinite(v))
            return mot_reject(mot, "%s %c must be a finite number, got %g",
                              what, mot_axis_letters[i], v);
    }
    return 0;
}

int mot_bad_cart(mot_t *mot, const char *what, const PmCartesian *c)
{
    if (!isfinite(c->x) || !isfinite(c->y) || !isfinite(c->z))
        return mot_reject(mot, "%s must be finite numbers, got (%g, %g, %g)",
                          what, c->x, c->y, c->z);
    return 0;
}

int mot_any_homing(mot_t *mot)
{
    int i;
    for (i = 0; i < mot->num_joints; i++)
        if (mot->home->is_homing(i))
            return 1;
    return 0;
}

/* ---- spindles ---- */
int mot_bad_spindle(mot_t *mot, int n)
{
    if (n < 0 || n >= mot->num_spindles)
        return mot_reject(mot, "spindle %d does not exist (num_spindles=%d)",
                          n, mot->num_spindles);
    return 0;
}

/* ---- coordinated moves ---- */
/* min_limit and max_limit of a SET_*_POSITION_LIMITS command */
int mot_bad_limits(mot_t *mot, const mot_command_t *c)
{
    int r;

    if ((r = mot_bad_pos(mot, "min_limit", c->min_limit))
        || (r = mot_bad_pos(mot, "max_limit", c->max_limit)))
        return r;
    if (c->min_limit > c->max_limit)
        return mot_reject(mot, "min_limit (%g) must not be above max_limit "
                          "(%g)", c->min_limit, c->max_limit);
    return 0;
}

/* ---- the dispatch table: command code -> handler ---- */
static mot_cmd_fn *const handlers[MOT_CMD_LAST] = {
    [MOT_CMD_ABORT] = mot_cmd_abort,
    [MOT_CMD_FREE] = mot_cmd_mode,
    [MOT_CMD_TELEOP] = mot_cmd_mode,
    [MOT_CMD_COORD] = mot_cmd_mode,
    [MOT_CMD_ENABLE] = mot_cmd_enable,
    [MOT_CMD_DISABLE] = mot_cmd_disable,
    [MOT_CMD_ENABLE_AMPLIFIER] = mot_cmd_amplifier,
    [MOT_CMD_DISABLE_AMPLIFIER] = mot_cmd_amplifier,
    [MOT_CMD_ACTIVATE_JOINT] = mot_cmd_activate_joint,
    [MOT_CMD_DEACTIVATE_JOINT] = mot_cmd_deactivate_joint,
    [MOT_CMD_PAUSE] = mot_cmd_pause,
    [MOT_CMD_RESUME] = mot_cmd_resume,
    [MOT_CMD_STEP] = mot_cmd_step,
    [MOT_CMD_SCALE] = mot_cmd_scale,
    [MOT_CMD_RAPID_SCALE] = mot_cmd_scale,
    [MOT_CMD_OVERRIDE_LIMITS] = mot_cmd_override_limits,
    [MOT_CMD_HOME] = mot_cmd_home,
    [MOT_CMD_UNHOME] = mot_cmd_unhome,
    [MOT_CMD_JOG_CONT] = mot_cmd_jog,
    [MOT_CMD_JOG_INCR] = mot_cmd_jog,
    [MOT_CMD_JOG_ABS] = mot_cmd_jog,
    [MOT_CMD_JOG_STOP] = mot_cmd_jog,
    [MOT_CMD_SET_LINE] = mot_cmd_move,
    [MOT_CMD_SET_CIRCLE] = mot_cmd_move,
    [MOT_CMD_PROBE] = mot_cmd_move,
    [MOT_CMD_SET_TELEOP_VECTOR] = mot_cmd_teleop_vector,
    [MOT_CMD_CLEAR_PROBE_FLAG] = mot_cmd_clear_probe_flag,
    [MOT_CMD_SET_NUM_JOINTS] = mot_cmd_set_num_joints,
    [MOT_CMD_SET_JOINT_POSITION_LIMITS] = mot_cmd_set_joint_position_limits,
    [MOT_CMD_SET_JOINT_VEL_LIMIT] = mot_cmd_set_joint_vel_limit,
    [MOT_CMD_SET_JOINT_ACC_LIMIT] = mot_cmd_set_joint_acc_limit,
    [MOT_CMD_SET_JOINT_JERK_LIMIT] = mot_cmd_set_joint_jerk_limit,
    [MOT_CMD_SET_JOINT_MIN_FERROR] = mot_cmd_set_joint_ferror,
    [MOT_CMD_SET_JOINT_MAX_FERROR] = mot_cmd_set_joint_ferror,
    [MOT_CMD_SET_JOINT_HOMING_PARAMS] = mot_cmd_set_joint_homing_params,
    [MOT_CMD_SET_JOINT_BACKLASH] = mot_cmd_set_joint_backlash,
    [MOT_CMD_SET_JOINT_COMP] = mot_cmd_joint_comp,
    [MOT_CMD_CLEAR_JOINT_COMP] = mot_cmd_joint_comp,
    [MOT_CMD_SET_JOINT_MOTOR_OFFSET] = mot_cmd_set_joint_motor_offset,
    [MOT_CMD_SET_AXIS_POSITION_LIMITS] = mot_cmd_set_axis_position_limits,
    [MOT_CMD_SET_AXIS_VEL_LIMIT] = mot_cmd_set_axis_vel_limit,
    [MOT_CMD_SET_AXIS_ACC_LIMIT] = mot_cmd_set_axis_acc_limit,
    [MOT_CMD_SET_AXIS_JERK_LIMIT] = mot_cmd_set_axis_jerk_limit,
    [MOT_CMD_SET_VEL] = mot_cmd_set_vel,
    [MOT_CMD_SET_VEL_LIMIT] = mot_cmd_set_vel_limit,
    [MOT_CMD_SET_ACC] = mot_cmd_set_acc,
    [MOT_CMD_SET_TERM_COND] = mot_cmd_set_term_cond,
    [MOT_CMD_SET_OFFSET] = mot_cmd_set_offset,
    [MOT_CMD_SET_PROFILE] = mot_cmd_set_profile,
    [MOT_CMD_SET_DOUT] = mot_cmd_set_dout,
    [MOT_CMD_SET_AOUT] = mot_cmd_set_aout,
    [MOT_CMD_SET_FEED_HOLD_ENABLE] = mot_cmd_feed_enables,
    [MOT_CMD_SET_ADAPTIVE_FEED_ENABLE] = mot_cmd_feed_enables,
    [MOT_CMD_SET_LINEAR_UNITS] = mot_cmd_set_linear_units,
    [MOT_CMD_SPINDLE_ON] = mot_cmd_spindle,
    [MOT_CMD_SPINDLE_OFF] = mot_cmd_spindle,
    [MOT_CMD_SPINDLE_INCREASE] = mot_cmd_spindle,
    [MOT_CMD_SPINDLE_DECREASE] = mot_cmd_spindle,
    [MOT_CMD_SPINDLE_ORIENT] = mot_cmd_spindle,
    [MOT_CMD_SPINDLE_BRAKE_ENGAGE] = mot_cmd_spindle,
    [MOT_CMD_SPINDLE_BRAKE_RELEASE] = mot_cmd_spindle,
    [MOT_CMD_SPINDLE_SYNC_LINE] = mot_cmd_move,
    [MOT_CMD_RIGID_TAP] = mot_cmd_move,
};

/* run one command (from the mailbox or the queue); an unknown or
   reserved code is refused */
static int run_command(mot_t *mot, const mot_command_t *c)
{
    mot_cmd_fn *fn = NULL;

    if (c->cmd >= 0 && c->cmd < MOT_CMD_LAST)
        fn = handlers[c->cmd];
    if (fn)
        return fn(mot, c);
    if (c->cmd >= MOT_CMD_RESERVED_FIRST && c->cmd <= MOT_CMD_RESERVED_LAST)
        return mot_reject(mot, "command %d is reserved and not implemented "
                          "yet", c->cmd);
    return mot_reject(mot, "unknown command code %d", c->cmd);
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

static int spindles_at_speed(mot_t *mot)
{
    int i;
    for (i = 0; i < mot->num_spindles; i++)
        if (mot->spindle[i].on && mot->spindle[i].speed != 0
            && !*mot->sp[i].at_speed)
            return 0;
    return 1;
}

void mot_queue_drop(mot_t *mot)
{
    mot_channel_t *ch = mot->chan;
    mot->deferred_valid = 0;            /* a held mailbox move goes too */
    if (!ch)
        return;
    __atomic_store_n(&ch->q_tail, __atomic_load_n(&ch->q_head,
                                                  __ATOMIC_ACQUIRE),
                     __ATOMIC_RELEASE);
}

static void queue_failed(mot_t *mot, mot_channel_t *ch, const mot_command_t *c,
                         const char *reason)
{
    ch->q_err_cmd = c->cmd;
    ch->q_err_id = c->id;
    ch->q_err_line = c->line;
    snprintf(ch->q_err_reason, sizeof(ch->q_err_reason), "%s", reason);
    mot_post(mot, "queued %s (id %d, line %d) rejected: %s; the rest of the "
             "queue is dropped", mot_cmd_name(c->cmd), c->id, c->line, reason);
    __atomic_store_n(&ch->q_err_count, ch->q_err_count + 1,
                     __ATOMIC_RELEASE);
}

static void drain_queue(mot_t *mot, mot_channel_t *ch)
{
    uint32_t head = __atomic_load_n(&ch->q_head, __ATOMIC_ACQUIRE);
    uint32_t tail = ch->q_tail;
    char w[MOT_REASON_LEN];
    mot_command_t c;
    int n = 0, st;

    if (head == tail)
        return;
    if (head - tail > MOT_QUEUE_SIZE) {
        mot_post(mot, "the move queue holds %u records, more than its %d "
                 "places (a client broke the protocol): dropped",
                 head - tail, MOT_QUEUE_SIZE);
        memset(&c, 0, sizeof(c));
        queue_failed(mot, ch, &c, "the move queue overflowed");
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
            if (!mot->tp_done || !spindles_at_speed(mot))
                break;
            mot->wait_at_speed = 0;
        }
        memcpy(&c, q, sizeof(c));
        mot->why = w;
        mot->whylen = sizeof(w);
        w[0] = 0;
        if (queueable(c.cmd))
            st = run_command(mot, &c);
        else
            st = mot_reject(mot, "%s cannot be queued (only moves and what "
                            "must keep its order with them)",
                            mot_cmd_name(c.cmd));
        tail++;
        n++;
        if (st == MOT_ECHO_REJECTED) {
            queue_failed(mot, ch, &c, w[0] ? w : "no reason given");
            /* the records after it have the old epoch: dropped in the
               next cycles (or right now) */
        }
    }
    __atomic_store_n(&ch->q_tail, tail, __ATOMIC_RELEASE);
}

/* hand the held mailbox move to the planner once its wait is over (or
   was cancelled by SPINDLE_OFF); a refusal then is posted */
static void run_deferred(mot_t *mot)
{
    char w[MOT_REASON_LEN];

    if (!mot->deferred_valid)
        return;
    if (!mot->enabled || mot->mode != MOT_MODE_COORD) {
        mot->deferred_valid = 0;
        return;
    }
    if (mot->wait_at_speed && (!mot->tp_done || !spindles_at_speed(mot)))
        return;
    mot->deferred_valid = 0;
    mot->wait_at_speed = 0;
    mot->why = w;
    mot->whylen = sizeof(w);
    w[0] = 0;
    if (run_command(mot, &mot->deferred) == MOT_ECHO_REJECTED)
        mot_post(mot, "%s (id %d, line %d), held until the spindle was at "
                 "speed, was refused: %s", mot_cmd_name(mot->deferred.cmd),
                 mot->deferred.id, mot->deferred.line, w);
}

void mot_command_handler(void *arg, long period)
{
    mot_t *mot = arg;
    mot_channel_t *ch = mot->chan;
    mot_command_t c;
    uint32_t seq;
    int st;

    (void)period;
    if (!ch)
        return;
    run_deferred(mot);
    seq = __atomic_load_n(&ch->cmd_seq, __ATOMIC_ACQUIRE);
    if (seq == mot->last_seq) {
        drain_queue(mot, ch);
        return;
    }
    memcpy(&c, (const void *)&ch->command, sizeof(c));
    mot->last_seq = seq;

    mot->why = ch->echo_reason;
    mot->whylen = sizeof(ch->echo_reason);
    mot->why[0] = 0;
    if (mot->wait_at_speed && waits_for_spindle(&c) && mot->enabled
        && mot->mode == MOT_MODE_COORD) {
        /* a feed move after a spindle start runs once the planner has
           run out and the spindles are at speed: answer now (ABORT must
           get through meanwhile) and hold the move */
        tp_move_t m;
        if (mot->deferred_valid)
            st = mot_reject(mot, "%s: a feed move already waits for the "
                            "spindle to reach speed", mot_cmd_name(c.cmd));
        else if ((st = mot_check_move(mot, &c, &m)) == MOT_ECHO_REJECTED)
            ;                           /* checked now, not after the wait */
        else {
            mot->deferred = c;
            mot->deferred_valid = 1;
            st = MOT_ECHO_ACCEPTED;
        }
    } else
        st = run_command(mot, &c);
    if (st != MOT_ECHO_REJECTED)
        mot->why[0] = 0;
    ch->echo_status = st;
    ch->echo_cmd = c.cmd;
    __atomic_store_n(&ch->echo_seq, seq, __ATOMIC_RELEASE);
    drain_queue(mot, ch);
}
