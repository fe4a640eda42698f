/*
 * tpmod.c - the coordinated-mode trajectory planner of motmod (tp.h).
 *
 * The queue holds segments: the programmed lines, circles/helices, probe
 * moves and rigid taps, and the blend arcs the planner inserts between
 * lines.  Each segment has a path length (parameter s), a velocity limit
 * vmax and a tangential acceleration limit amax derived from the move and
 * from every axis's limits, and a "junction cap" at its end: the highest
 * velocity at which the path may pass into the next segment.
 *
 * Path control (term_cond of the move whose end it is):
 *   TP_TERM_STOP   cap 0: the machine comes to rest (and rests one cycle).
 *   TP_TERM_EXACT  the path is never left.  A junction may be passed at a
 *                  speed v only if the change of direction it makes in the
 *                  sampled path needs at most half of each axis's
 *                  acceleration: v |du_i| <= a_i dt / 2, du = the jump of
 *                  the unit tangent (per axis).  Tangent junctions keep
 *                  their speed; a corner whose speed would be below two
 *                  acceleration steps is an exact stop.
 *   TP_TERM_BLEND  between two lines (only XYZ moving) the corner is
 *                  replaced by a tangent circular arc.  For a turn angle
 *                  t the arc of radius R passes R (1 - cos(t/2)) from
 *                  both lines (the distance from the programmed path, as
 *                  G64 P means it); its ends are d = R tan(t/2) from the
 *                  corner; R is the largest with that distance within the
 *                  tolerance and d at most half of either line (so the
 *                  blends of both ends of a line never overlap).
 *                  Tolerance 0: d = half of the shorter line.  Other
 *                  corners (arcs, rotary/UVW axes) use the exact-path
 *                  rule.  With cam_tolerance Q, consecutive lines whose
 *                  vertices stay within Q of one line are merged.
 *
 * Limits.  On a line every axis moves in proportion to s (factor |u_i|),
 * so v <= v_i / |u_i| and the tangential acceleration <= a_i / |u_i|.  On
 * an arc each XYZ axis's acceleration is split between the tangential
 * part and the centripetal one (v^2 / R times the axis's share of the
 * plane): half each on programmed arcs, BLEND_SHARE for the centripetal
 * part on blend arcs (their speed hardly changes); the velocity limit
 * follows from the centripetal part.
 *
 * Look-ahead.  Each segment has vend, the highest velocity at its end from
 * which every later junction cap and the end of the queue (where the
 * machine must be able to stop) can be met: a backward pass
 * vend[k] = min(cap[k], sqrt(vend[k+1]^2 + 2 a L[k+1])) (reach_vel: with a
 * 10 % margin on a, less one step on long segments) run on every queued
 * move, stopping as soon as a value no longer changes.  Every cycle the
 * planner walks forward from where it is over the junctions within its
 * stopping distance (at most MAX_WALK segments), composes their limits
 * the same way, and picks the highest velocity that is within one
 * acceleration step of the last one, within the requested (scaled)
 * velocity, and from which a discrete staircase of decelerations (one
 * step per cycle, in whole cycles) reaches the next junction at no more
 * than its velocity.  A cycle that passes a junction with a change of
 * direction or curvature (and the cycle after it) changes the path
 * velocity by at most half the acceleration of the segments it touches,
 * so that the direction change fits in the other half; the velocity of
 * the cycle before such a junction is planned for that.  Segments shorter
 * than a few cycles of travel next to a corner are planned with half
 * their acceleration (every cycle there may pass a junction).  In one
 * cycle the planner passes as many junctions as the distance of the cycle
 * covers (short CAM segments).
 *
 * Jerk (tp_move_t.jerk > 0): such moves are not blended and stop at
 * every change of direction or curvature; along the path each cycle
 * follows the most restrictive of the time-optimal jerk-limited profiles
 * (ruckig, tp_jerk.cpp) toward the requested velocity and toward the next
 * junctions at their velocities.
 *
 * Spindle synchronized moves follow the spindle's revolutions exactly
 * (distance = pitch x revs since the start); they start and end at rest. *
 * The sources follow these steps (tp_priv.h): tp_geom.c the segments and
 * their limits, tp_lookahead.c the junctions and the backward pass,
 * tp_blend.c blend arcs and merges, tp_queue.c the queue, tp_cycle.c one
 * cycle; this file holds the module, its parameters, the planner state
 * (one tp_t, handed to every function of the others) and the tp.h
 * interface.
 */

#include "rtapi.h"
#include "rtapi_app.h"
#include "tp_priv.h"

MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("Blending look-ahead trajectory planner for motmod");
MODULE_LICENSE("GPL");

static char *tp_parms = "";
RTAPI_MP_STRING(tp_parms, "accepted for compatibility, not used");
static int queue_size = 2000;
RTAPI_MP_INT(queue_size, "number of moves the queue holds (200..1000000)");

static int own_id;              /* the tpmod component */

/* the planner: the only tp_t; every function of the other sources gets
   it as an argument (tp_priv.h) */
static tp_t tp;

/* ---------------------------------------------------------------- helpers */

int why_(char *why, int len, int ret, const char *fmt, ...)
{
    va_list ap;
    if (why && len > 0) {
        va_start(ap, fmt);
        rtapi_vsnprintf(why, len, fmt, ap);
        va_end(ap);
    }
    return ret;
}

/* ------------------------------------------------------------------- API */

static int tp_init(int comp_id, double traj_period, const tp_hooks_t *hooks,
                   char *why, int whylen)
{
    int i;
    if (!tp.q)
        return why_(why, whylen, -ENODEV, "tpmod has no queue memory");
    if (!(isfinite(traj_period) && traj_period > 0 && traj_period < 1))
        return why_(why, whylen, -EINVAL,
                    "bad trajectory period %g s", traj_period);
    tp.comp_id = comp_id;
    tp.dt = traj_period;
    if (hooks)
        tp.hooks = *hooks;
    else
        memset(&tp.hooks, 0, sizeof(tp.hooks));
    tp.vel_limit = 0;
    for (i = 0; i < NAX; i++) {
        tp.ax_vel[i] = tp.ax_acc[i] = 0;
        tp.pos[i] = tp.last_vel[i] = 0;
    }
    tp.feed_scale = tp.rapid_scale = 1;
    tp.in_feed = 1;
    tp.rt_reversed = 0;
    flush_queue(&tp);
    tp.exec_id = 0;
    tp.motion_type = 0;
    tp.probe_result = 0;
    tp.err[0] = 0;
    tp.inited = 1;
    return 0;
}

static void tp_set_vel_limit(double vel)
{
    tp.vel_limit = isfinite(vel) && vel > 0 ? vel : 0;
}

static void tp_set_axis_limits(int axis, double vel, double acc)
{
    if (axis < 0 || axis >= NAX)
        return;
    tp.ax_vel[axis] = isfinite(vel) && vel > 0 ? vel : 0;
    tp.ax_acc[axis] = isfinite(acc) && acc > 0 ? acc : 0;
}

static int tp_set_pos(const EmcPose *pos, char *why, int whylen)
{
    int i;
    if (!pos || !finite_pose(pos))
        return why_(why, whylen, -EINVAL,
                    "the position is not a finite number in every axis");
    if (tp.count > 0 || tp.v != 0)
        return why_(why, whylen, -EBUSY,
                    "the planner position cannot change while moves are "
                    "queued");
    pose_to(pos, tp.pos);
    for (i = 0; i < NAX; i++)
        tp.last_vel[i] = 0;
    return 0;
}

static void tp_get_pos(EmcPose *pos)
{
    to_pose(tp.pos, pos);
}

static int tp_add_line(const EmcPose *end, const tp_move_t *m,
                       char *why, int whylen)
{
    return queue_line(&tp, end, m, -1, 0, why, whylen);
}

static int tp_add_circle(const EmcPose *end, const PmCartesian *center,
                         const PmCartesian *normal, int turn,
                         const tp_move_t *m, char *why, int whylen)
{
    return queue_circle(&tp, end, center, normal, turn, m, why, whylen);
}

static int tp_add_probe(const EmcPose *end, const tp_move_t *m,
                        int probe_type, char *why, int whylen)
{
    if (probe_type & ~(TP_PROBE_NO_ERROR | TP_PROBE_AWAY))
        return why_(why, whylen, -EINVAL, "unknown probe type %d",
                    probe_type);
    return queue_line(&tp, end, m, probe_type, 0, why, whylen);
}

static int tp_add_rigid_tap(const EmcPose *end, const tp_move_t *m,
                            char *why, int whylen)
{
    tp_move_t mm;
    if (!m)
        return why_(why, whylen, -EINVAL, "no move data");
    if (!tp.hooks.spindle_reverse)
        return why_(why, whylen, -ENOTSUP,
                    "rigid tapping needs the spindle_reverse hook");
    mm = *m;
    if (mm.sync == TP_SYNC_NONE)
        mm.sync = TP_SYNC_POSITION;
    mm.term_cond = TP_TERM_STOP;
    return queue_line(&tp, end, &mm, -1, 1, why, whylen);
}

static int tp_sync_out(int analog, int index, double value, int now)
{
    sync_ev_t *e;
    if (index < 0 || index >= 64 || !isfinite(value))
        return -EINVAL;
    if (now) {
        if (analog && tp.hooks.set_aout)
            tp.hooks.set_aout(index, value);
        else if (!analog && tp.hooks.set_dout)
            tp.hooks.set_dout(index, value != 0);
        return 0;
    }
    if (tp.ev_count >= NSYNC)
        return -ENOSPC;
    e = &tp.ev[(tp.ev_head + tp.ev_count) % NSYNC];
    e->seq = tp.next_seq;
    e->analog = analog;
    e->index = index;
    e->value = value;
    tp.ev_count++;
    return 0;
}

static int tp_set_dout(int index, int value, int now)
{
    return tp_sync_out(0, index, value != 0, now);
}

static int tp_set_aout(int index, double value, int now)
{
    return tp_sync_out(1, index, value, now);
}

static void tp_abort(void)
{
    if (tp.count == 0 || tp.v == 0)
        flush_queue(&tp);
    else
        tp.aborting = 1;
}

static void tp_reset(void)
{
    int i;
    flush_queue(&tp);
    tp.a = 0;
    for (i = 0; i < NAX; i++)
        tp.last_vel[i] = 0;
}

static void tp_pause(void)
{
    tp.pausing = 1;
    tp.resume_after_step = 0;
    /* (a machine already stopping at the end of a step keeps that stop:
       without it, that end may be a junction it cannot pass any more) */
    if (tp.v <= 0)
        tp.stepping = 0;
}

static void tp_resume(void)
{
    tp.pausing = 0;
    /* a machine already stopping at the end of a step stops there and
       goes on at once (that end may be a junction it cannot pass any
       more) */
    if (tp.stepping && tp.v > 0)
        tp.resume_after_step = 1;
    else
        tp.stepping = 0;
}

static void tp_step(void)
{
    if (tp.count == 0)
        return;
    tp.pausing = 0;
    tp.stepping = 1;
    tp.resume_after_step = 0;
    /* the move running (or the next one), or the first one at whose end
       the machine can still stop */
    tp.step_seq = seg(&tp, 0)->seq;
    tp.step_new = 1;
}

static void tp_set_scale(double feed, double rapid)
{
    tp.feed_scale = isfinite(feed) && feed > 0 ? feed : 0;
    tp.rapid_scale = isfinite(rapid) && rapid > 0 ? rapid : 0;
}

/* the junctions of one look-ahead walk */
static struct {
    double dist;                /* from here to the end of the segment */
    double vf;                  /* velocity limit at the junction */
    double ws;                  /* the next segment's requested velocity */
    int stop;
    int composed;               /* vf comes from later junctions */
} wk[MAX_WALK];

static void tp_run_cycle(const tp_inputs_t *in, EmcPose *out)
{
    run_cycle(&tp, in, out);
}

static double tp_distance_to_go(void)
{
    double d;
    int k;
    if (tp.count == 0)
        return 0;
    d = seg(&tp, 0)->len - tp.s;
    for (k = 1; k < tp.count && k < 4 &&
         seg(&tp, k)->seq == seg(&tp, 0)->seq; k++)
        d += seg(&tp, k)->len;
    if (seg(&tp, 0)->rigid)
        d = fabs(seg(&tp, 0)->len - tp.s);
    return d;
}

static void tp_get_state(tp_state_t *st)
{
    double d[NAX];
    int i, k;
    tc_t *t = tp.count ? seg(&tp, 0) : NULL;

    memset(st, 0, sizeof(*st));
    st->vel = tp.v;
    st->acc = tp.a;
    st->dtg = tp_distance_to_go();
    if (t) {
        for (k = 0; k + 1 < tp.count && k < 4 &&
             seg(&tp, k + 1)->seq == t->seq; k++)
            ;
        for (i = 0; i < NAX; i++)
            d[i] = seg(&tp, k)->end[i] - tp.pos[i];
    } else {
        for (i = 0; i < NAX; i++)
            d[i] = 0;
    }
    to_pose(d, &st->dtg_pose);
    to_pose(tp.last_vel, &st->vel_pose);
    st->exec_id = tp.exec_id;
    st->motion_type = t ? t->m.type : 0;
    st->queue_depth = tp.moves;
    st->done = tp.count == 0 && tp.v == 0;
    st->paused = tp.pausing && tp.v == 0;
    st->probing = t && tp.started && t->probe_type >= 0;
    st->requested_vel = tp.reqv;
    st->active_moves = tp.active;
    st->waiting = tp.waiting;
    st->spindle_sync = t && tp.started && t->m.sync != TP_SYNC_NONE;
    st->rigid_tap_reversed = tp.rt_reversed;
    st->feed_scale = tp.in_hold || tp.in_inhibit ? 0 : tp.in_feed;
}

static int tp_is_done(void)
{
    return tp.count == 0 && tp.v == 0;
}

static int tp_queue_depth(void)
{
    return tp.moves;
}

static int tp_queue_space(void)
{
    int a = queue_size - tp.moves;
    int b = (tp.nslots - tp.count) / 2;
    return a < b ? a : b;
}

static int tp_exec_id(void)
{
    return tp.exec_id;
}

static double tp_current_vel(void)
{
    return tp.v;
}

static int tp_probe_result(EmcPose *pos)
{
    if (pos && tp.probe_result == 1)
        to_pose(tp.probe_pos, pos);
    return tp.probe_result;
}

static void tp_clear_probe(void)
{
    tp.probe_result = 0;
}

static const char *tp_take_error(void)
{
    static char buf[sizeof(tp.err)];
    rtapi_snprintf(buf, sizeof(buf), "%s", tp.err);
    tp.err[0] = 0;
    return buf;
}

const halsdk_tp_api_t halsdk_tp_api = {
    .version = HALSDK_TP_VERSION,
    .init = tp_init,
    .set_vel_limit = tp_set_vel_limit,
    .set_axis_limits = tp_set_axis_limits,
    .set_pos = tp_set_pos,
    .get_pos = tp_get_pos,
    .add_line = tp_add_line,
    .add_circle = tp_add_circle,
    .add_probe = tp_add_probe,
    .set_dout = tp_set_dout,
    .set_aout = tp_set_aout,
    .abort = tp_abort,
    .pause = tp_pause,
    .resume = tp_resume,
    .step = tp_step,
    .set_scale = tp_set_scale,
    .run_cycle = tp_run_cycle,
    .get_state = tp_get_state,
    .is_done = tp_is_done,
    .queue_depth = tp_queue_depth,
    .queue_space = tp_queue_space,
    .exec_id = tp_exec_id,
    .distance_to_go = tp_distance_to_go,
    .current_vel = tp_current_vel,
    .probe_result = tp_probe_result,
    .clear_probe = tp_clear_probe,
    .take_error = tp_take_error,
    .reset = tp_reset,
    .add_rigid_tap = tp_add_rigid_tap,
};
EXPORT_SYMBOL(halsdk_tp_api);

/* ---------------------------------------------------------------- module */

int rtapi_app_main(void)
{
    if (queue_size < 200 || queue_size > 1000000) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "tpmod: queue_size=%d is out of range 200..1000000\n",
                        queue_size);
        return -EINVAL;
    }
    own_id = hal_init("tpmod");
    if (own_id < 0)
        return own_id;
    tp.queue_size = queue_size;
    /* every programmed line may bring a blend arc */
    tp.nslots = 2 * queue_size + 4;
    tp.q = hal_malloc((long)tp.nslots * sizeof(tc_t));
    if (!tp.q) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "tpmod: no memory for a queue of %d moves\n",
                        queue_size);
        hal_exit(own_id);
        return -ENOMEM;
    }
    hal_ready(own_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(own_id);
}
