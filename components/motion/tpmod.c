/*
 * tpmod.c - a simple coordinated-mode trajectory planner.
 *
 * Every queued move is run on its own and ends at rest (exact stop): the
 * path velocity follows a trapezoid along the path length under the
 * move's velocity and acceleration, the feed or rapid scale, the machine
 * velocity limit and the per-axis limits.  Pause and abort decelerate
 * along the path within the acceleration limit.  Lines move all nine
 * axes; the path length is the XYZ distance, or the UVW distance, or the
 * ABC distance when only those axes move.  Circles and helices lie in
 * any plane (given by its normal).  The interface is tp.h; motmod finds
 * the table halsdk_tp_api when it loads.
 *
 * The velocity profile is computed in discrete time: each cycle the
 * velocity changes by at most acc * dt, and the highest velocity that
 * can still stop exactly at the end of the move in whole cycles is
 * known in closed form, so a move ends exactly at its end point without
 * exceeding the acceleration in the last cycles.
 */

#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_math.h"
#include "rtapi_string.h"
#include "hal.h"
#include "tp.h"

MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("Exact-stop trajectory planner for motmod");
MODULE_LICENSE("GPL");

static char *tp_parms = "";
RTAPI_MP_STRING(tp_parms, "accepted for compatibility, not used");
static int queue_size = 2000;
RTAPI_MP_INT(queue_size, "number of moves the queue holds (200..1000000)");

#define NAX 9                   /* X Y Z A B C U V W */
#define EPS 1e-12               /* shorter than this: no motion */
#define NSYNC 256               /* pending synchronized outputs */

enum { TC_LINE, TC_CIRCLE };

typedef struct {
    int kind;                   /* TC_LINE or TC_CIRCLE */
    tp_move_t m;
    int probe_type;             /* TP_PROBE_* bits; -1: not a probe */
    unsigned long seq;          /* number of the move since load */
    double start[NAX], end[NAX];
    double len;                 /* path length (parameter s: 0..len) */
    double vmax;                /* velocity limit from geometry and axes */
    double amax;                /* tangential acceleration limit */
    /* circle: center, unit normal, unit start direction u, w = n x u */
    double c[3], n[3], u[3], w[3];
    double r0, r1;              /* start and end radius */
    double h0, h1;              /* start and end height along n */
    double angle;               /* swept angle, > 0 */
} tc_t;

typedef struct {
    unsigned long seq;          /* fire when this move starts */
    int analog;
    int index;
    double value;
} sync_ev_t;

static int own_id;              /* the tpmod component */

static struct {
    int comp_id;                /* motmod's, from init() */
    int inited;
    double dt;
    tp_hooks_t hooks;
    double vel_limit;
    double ax_vel[NAX], ax_acc[NAX];
    double feed_scale, rapid_scale;

    tc_t *q;                    /* ring of queue_size moves (hal_malloc) */
    int head, count;
    unsigned long next_seq;
    int started;                /* the head move has started */
    double s, v, a;             /* progress along the head move */

    double pos[NAX];            /* commanded position */
    double last_vel[NAX];
    int aborting, pausing, stepping;
    int exec_id, motion_type;

    int probe_result;
    double probe_pos[NAX];

    sync_ev_t ev[NSYNC];
    int ev_head, ev_count;

    char err[128];
} tp;

/* ---------------------------------------------------------------- helpers */

static void pose_to(const EmcPose *p, double *v)
{
    int i;
    for (i = 0; i < NAX; i++)
        v[i] = *emcpose_axis((EmcPose *)p, i);
}

static void to_pose(const double *v, EmcPose *p)
{
    int i;
    for (i = 0; i < NAX; i++)
        *emcpose_axis(p, i) = v[i];
}

static int why_(char *why, int len, int ret, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static int why_(char *why, int len, int ret, const char *fmt, ...)
{
    va_list ap;
    if (why && len > 0) {
        va_start(ap, fmt);
        rtapi_vsnprintf(why, len, fmt, ap);
        va_end(ap);
    }
    return ret;
}

static void set_error(const char *msg)
{
    rtapi_snprintf(tp.err, sizeof(tp.err), "%s", msg);
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double norm3(const double *a)
{
    return sqrt(dot3(a, a));
}

static int finite_pose(const EmcPose *p)
{
    double v[NAX];
    int i;
    pose_to(p, v);
    for (i = 0; i < NAX; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* the end of the last queued move, or where we are */
static const double *queue_end(void)
{
    if (tp.count == 0)
        return tp.pos;
    return tp.q[(tp.head + tp.count - 1) % queue_size].end;
}

static int check_move(const tp_move_t *m, char *why, int whylen)
{
    if (!m)
        return why_(why, whylen, -EINVAL, "no move data");
    if (!(isfinite(m->vel) && m->vel > 0))
        return why_(why, whylen, -EINVAL,
                    "velocity must be a positive number (got %g)", m->vel);
    if (!(isfinite(m->ini_maxvel) && m->ini_maxvel > 0))
        return why_(why, whylen, -EINVAL,
                    "maximum velocity must be a positive number (got %g)",
                    m->ini_maxvel);
    if (!(isfinite(m->acc) && m->acc > 0))
        return why_(why, whylen, -EINVAL,
                    "acceleration must be a positive number (got %g)",
                    m->acc);
    if (!(isfinite(m->jerk) && m->jerk >= 0))
        return why_(why, whylen, -EINVAL,
                    "jerk must be zero or a positive number (got %g)",
                    m->jerk);
    if (m->type < TP_MOTION_TRAVERSE || m->type > TP_MOTION_INDEXROTARY)
        return why_(why, whylen, -EINVAL, "unknown motion type %d",
                    m->type);
    if (m->term_cond < TP_TERM_STOP || m->term_cond > TP_TERM_BLEND)
        return why_(why, whylen, -EINVAL,
                    "unknown end-of-move condition %d", m->term_cond);
    if (!(isfinite(m->tolerance) && m->tolerance >= 0))
        return why_(why, whylen, -EINVAL,
                    "blend tolerance must be zero or positive (got %g)",
                    m->tolerance);
    return 0;
}

static int check_room(char *why, int whylen)
{
    if (!tp.inited)
        return why_(why, whylen, -ENODEV,
                    "the trajectory planner is not initialized");
    if (tp.aborting)
        return why_(why, whylen, -EBUSY,
                    "the trajectory planner is aborting");
    if (tp.count >= queue_size)
        return why_(why, whylen, -ENOSPC,
                    "the motion queue is full (%d moves)", queue_size);
    return 0;
}

/* lower vmax/amax so that an axis moving delta over the path length len
   stays within its limits */
static void axis_share(tc_t *tc, int i, double delta, double len)
{
    double f = fabs(delta) / len;
    if (f < EPS)
        return;
    if (tp.ax_vel[i] > 0 && tp.ax_vel[i] / f < tc->vmax)
        tc->vmax = tp.ax_vel[i] / f;
    if (tp.ax_acc[i] > 0 && tp.ax_acc[i] / f < tc->amax)
        tc->amax = tp.ax_acc[i] / f;
}

static tc_t *new_tc(const tp_move_t *m, int kind, const EmcPose *end)
{
    tc_t *tc = &tp.q[(tp.head + tp.count) % queue_size];
    const double *st = queue_end();
    int i;

    memset(tc, 0, sizeof(*tc));
    tc->kind = kind;
    tc->m = *m;
    tc->probe_type = -1;
    for (i = 0; i < NAX; i++)
        tc->start[i] = st[i];
    pose_to(end, tc->end);
    tc->vmax = m->ini_maxvel;
    tc->amax = m->acc;
    return tc;
}

static void commit_tc(tc_t *tc)
{
    tc->seq = tp.next_seq++;
    tp.count++;
}

/* -------------------------------------------------------------- geometry */

static void line_setup(tc_t *tc)
{
    double d[NAX];
    double lx, lu, la;
    int i;

    for (i = 0; i < NAX; i++)
        d[i] = tc->end[i] - tc->start[i];
    lx = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    la = sqrt(d[3] * d[3] + d[4] * d[4] + d[5] * d[5]);
    lu = sqrt(d[6] * d[6] + d[7] * d[7] + d[8] * d[8]);
    tc->len = lx > EPS ? lx : lu > EPS ? lu : la > EPS ? la : 0;
    if (tc->len > 0)
        for (i = 0; i < NAX; i++)
            axis_share(tc, i, d[i], tc->len);
}

static void line_eval(const tc_t *tc, double s, double *p)
{
    double f = tc->len > 0 ? s / tc->len : 1;
    int i;
    for (i = 0; i < NAX; i++)
        p[i] = tc->start[i] + (tc->end[i] - tc->start[i]) * f;
}

static int circle_setup(tc_t *tc, const PmCartesian *center,
                        const PmCartesian *normal, int turn,
                        char *why, int whylen)
{
    double r0v[3], r1v[3], e[3];
    double nn, ang, rmax, rmin, dh, an, v;
    int i;

    tc->c[0] = center->x;
    tc->c[1] = center->y;
    tc->c[2] = center->z;
    tc->n[0] = normal->x;
    tc->n[1] = normal->y;
    tc->n[2] = normal->z;
    nn = norm3(tc->n);
    if (!(nn > EPS))
        return why_(why, whylen, -EINVAL, "the circle's normal is zero");
    for (i = 0; i < 3; i++) {
        tc->n[i] /= nn;
        r0v[i] = tc->start[i] - tc->c[i];
        r1v[i] = tc->end[i] - tc->c[i];
    }
    tc->h0 = dot3(r0v, tc->n);
    tc->h1 = dot3(r1v, tc->n);
    for (i = 0; i < 3; i++) {
        r0v[i] -= tc->h0 * tc->n[i];
        r1v[i] -= tc->h1 * tc->n[i];
    }
    tc->r0 = norm3(r0v);
    tc->r1 = norm3(r1v);
    if (tc->r0 < 1e-9)
        return why_(why, whylen, -EINVAL,
                    "the circle's start point lies on its axis "
                    "(radius zero)");
    if (tc->r1 < 1e-9)
        return why_(why, whylen, -EINVAL,
                    "the circle's end point lies on its axis "
                    "(radius zero)");
    for (i = 0; i < 3; i++)
        tc->u[i] = r0v[i] / tc->r0;
    tc->w[0] = tc->n[1] * tc->u[2] - tc->n[2] * tc->u[1];
    tc->w[1] = tc->n[2] * tc->u[0] - tc->n[0] * tc->u[2];
    tc->w[2] = tc->n[0] * tc->u[1] - tc->n[1] * tc->u[0];
    for (i = 0; i < 3; i++)
        e[i] = r1v[i] / tc->r1;
    ang = atan2(dot3(e, tc->w), dot3(e, tc->u));
    if (ang <= 1e-12)
        ang += 2 * M_PI;
    tc->angle = ang + 2 * M_PI * turn;

    /* length: the helix on the larger radius (the speed along the path is
       then never above the planned one, also on a spiral) */
    rmax = tc->r0 > tc->r1 ? tc->r0 : tc->r1;
    rmin = tc->r0 < tc->r1 ? tc->r0 : tc->r1;
    dh = tc->h1 - tc->h0;
    tc->len = sqrt(rmax * tc->angle * rmax * tc->angle + dh * dh);

    /* XYZ axes: each moves no faster than the path and accelerates no
       more than the total acceleration */
    for (i = 0; i < 3; i++) {
        if (fabs(tc->u[i]) + fabs(tc->w[i]) < EPS &&
            fabs(tc->n[i] * dh) < EPS)
            continue;
        if (tp.ax_vel[i] > 0 && tp.ax_vel[i] < tc->vmax)
            tc->vmax = tp.ax_vel[i];
        if (tp.ax_acc[i] > 0 && tp.ax_acc[i] < tc->amax)
            tc->amax = tp.ax_acc[i];
    }
    /* the other axes move in proportion to the path; the tangential
       acceleration is half the total (below) */
    for (i = 3; i < NAX; i++) {
        double f = fabs(tc->end[i] - tc->start[i]) / tc->len;
        if (f < EPS)
            continue;
        if (tp.ax_vel[i] > 0 && tp.ax_vel[i] / f < tc->vmax)
            tc->vmax = tp.ax_vel[i] / f;
        if (tp.ax_acc[i] > 0 && 2 * tp.ax_acc[i] / f < tc->amax)
            tc->amax = 2 * tp.ax_acc[i] / f;
    }
    /* centripetal acceleration at most sqrt(3)/2 of the total, the
       tangential one at most half: together at most the total */
    an = tc->amax * 0.8660254037844386;
    v = sqrt(an * rmin) * tc->len / (rmax * tc->angle);
    if (v < tc->vmax)
        tc->vmax = v;
    tc->amax *= 0.5;
    return 0;
}

static void circle_eval(const tc_t *tc, double s, double *p)
{
    double f = s / tc->len;
    double ph = f * tc->angle;
    double r = tc->r0 + (tc->r1 - tc->r0) * f;
    double h = tc->h0 + (tc->h1 - tc->h0) * f;
    double cs = cos(ph), sn = sin(ph);
    int i;

    for (i = 0; i < 3; i++)
        p[i] = tc->c[i] + r * (cs * tc->u[i] + sn * tc->w[i]) +
            h * tc->n[i];
    for (i = 3; i < NAX; i++)
        p[i] = tc->start[i] + (tc->end[i] - tc->start[i]) * f;
}

static void tc_eval(const tc_t *tc, double s, double *p)
{
    int i;
    if (s >= tc->len) {
        for (i = 0; i < NAX; i++)
            p[i] = tc->end[i];
    } else if (tc->kind == TC_CIRCLE) {
        circle_eval(tc, s, p);
    } else {
        line_eval(tc, s, p);
    }
}

/* ----------------------------------------------------------------- queue */

static void fire_sync(unsigned long seq)
{
    while (tp.ev_count > 0) {
        sync_ev_t *e = &tp.ev[tp.ev_head];
        if ((long)(e->seq - seq) > 0)
            break;
        if (e->analog && tp.hooks.set_aout)
            tp.hooks.set_aout(e->index, e->value);
        else if (!e->analog && tp.hooks.set_dout)
            tp.hooks.set_dout(e->index, (int)e->value);
        tp.ev_head = (tp.ev_head + 1) % NSYNC;
        tp.ev_count--;
    }
}

static void flush_queue(void)
{
    tp.head = 0;
    tp.count = 0;
    tp.started = 0;
    tp.s = tp.v = tp.a = 0;
    tp.ev_head = tp.ev_count = 0;
    tp.aborting = 0;
    tp.pausing = 0;
    tp.stepping = 0;
}

static void pop_tc(void)
{
    tp.head = (tp.head + 1) % queue_size;
    tp.count--;
    tp.started = 0;
    tp.s = 0;
}

/* the highest velocity v for this cycle after which the rest d of the
   move can still be covered stopping in whole cycles with decelerations
   of at most acc (v, v - acc*dt, v - 2*acc*dt, ... sum to d / dt) */
static double stop_vel(double d, double acc, double dt)
{
    double D, k, frac;

    if (d <= 0)
        return 0;
    D = d / (acc * dt * dt);
    if (D > 1e15)               /* far from the end: the continuous
                                   formula is exact enough (and k below
                                   would lose integer precision) */
        return sqrt(2 * d * acc) - 0.5 * acc * dt;
    k = floor((sqrt(1 + 8 * D) - 1) / 2);
    /* rounding: make sure k (k + 1) / 2 <= D < (k + 1) (k + 2) / 2 */
    while (k > 0 && k * (k + 1) / 2 > D)
        k--;
    while ((k + 1) * (k + 2) / 2 <= D)
        k++;
    frac = (D - k * (k + 1) / 2) / (k + 1);
    return (k + frac) * acc * dt;
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
    flush_queue();
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
    tc_t *tc;
    int r;

    if ((r = check_room(why, whylen)) < 0)
        return r;
    if ((r = check_move(m, why, whylen)) < 0)
        return r;
    if (!end || !finite_pose(end))
        return why_(why, whylen, -EINVAL,
                    "the end point is not a finite number in every axis");
    tc = new_tc(m, TC_LINE, end);
    line_setup(tc);
    commit_tc(tc);
    return 0;
}

static int tp_add_circle(const EmcPose *end, const PmCartesian *center,
                         const PmCartesian *normal, int turn,
                         const tp_move_t *m, char *why, int whylen)
{
    tc_t *tc;
    int r;

    if ((r = check_room(why, whylen)) < 0)
        return r;
    if ((r = check_move(m, why, whylen)) < 0)
        return r;
    if (!end || !finite_pose(end))
        return why_(why, whylen, -EINVAL,
                    "the end point is not a finite number in every axis");
    if (!center || !normal || !isfinite(center->x) || !isfinite(center->y)
        || !isfinite(center->z) || !isfinite(normal->x)
        || !isfinite(normal->y) || !isfinite(normal->z))
        return why_(why, whylen, -EINVAL,
                    "the circle's center and normal must be finite");
    if (turn < 0 || turn > 100000)
        return why_(why, whylen, -EINVAL,
                    "extra turns must be 0..100000 (got %d)", turn);
    tc = new_tc(m, TC_CIRCLE, end);
    if ((r = circle_setup(tc, center, normal, turn, why, whylen)) < 0)
        return r;
    commit_tc(tc);
    return 0;
}

static int tp_add_probe(const EmcPose *end, const tp_move_t *m,
                        int probe_type, char *why, int whylen)
{
    tc_t *tc;
    int r;

    if ((r = check_room(why, whylen)) < 0)
        return r;
    if ((r = check_move(m, why, whylen)) < 0)
        return r;
    if (!end || !finite_pose(end))
        return why_(why, whylen, -EINVAL,
                    "the end point is not a finite number in every axis");
    if (probe_type & ~(TP_PROBE_NO_ERROR | TP_PROBE_AWAY))
        return why_(why, whylen, -EINVAL, "unknown probe type %d",
                    probe_type);
    tc = new_tc(m, TC_LINE, end);
    tc->m.type = TP_MOTION_PROBING;
    tc->probe_type = probe_type;
    line_setup(tc);
    commit_tc(tc);
    return 0;
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
        flush_queue();
    else
        tp.aborting = 1;
}

static void tp_pause(void)
{
    tp.pausing = 1;
}

static void tp_resume(void)
{
    tp.pausing = 0;
    tp.stepping = 0;
}

static void tp_step(void)
{
    tp.pausing = 0;
    tp.stepping = 1;
}

static void tp_set_scale(double feed, double rapid)
{
    tp.feed_scale = isfinite(feed) && feed > 0 ? feed : 0;
    tp.rapid_scale = isfinite(rapid) && rapid > 0 ? rapid : 0;
}

/* the velocity the head move wants now */
static double want_vel(const tc_t *tc)
{
    double v = tc->m.vel;
    if (!(tc->m.flags & TP_MOVE_NO_FEED_SCALE))
        v *= tc->m.type == TP_MOTION_TRAVERSE ? tp.rapid_scale
                                               : tp.feed_scale;
    if (v > tc->vmax)
        v = tc->vmax;
    if (tp.vel_limit > 0 && v > tp.vel_limit)
        v = tp.vel_limit;
    if (tp.aborting || tp.pausing)
        v = 0;
    return v;
}

static void tp_run_cycle(const tp_inputs_t *in, EmcPose *out)
{
    double prev[NAX], dt = tp.dt;
    double vt, vs, nv, left;
    int i, tripped, finished = 0;
    tc_t *tc;

    for (i = 0; i < NAX; i++)
        prev[i] = tp.pos[i];
    if (!tp.inited || tp.count == 0) {
        tp.v = tp.a = 0;
        tp.aborting = 0;
        goto out;
    }
    tc = &tp.q[tp.head];
    tripped = 0;
    if (tc->probe_type >= 0 && in)
        tripped = (tc->probe_type & TP_PROBE_AWAY) ? !in->probe_input
                                                   : in->probe_input != 0;
    if (!tp.started) {
        if (tp.aborting || (tp.pausing && !tp.stepping))
            goto stopped;
        tp.started = 1;
        tp.s = 0;
        tp.exec_id = tc->m.id;
        tp.motion_type = tc->m.type;
        fire_sync(tc->seq);
        if (tc->probe_type >= 0) {
            tp.probe_result = 0;
            if (tripped) {
                set_error("the probe is already tripped when the probe "
                          "move starts");
                flush_queue();
                goto out;
            }
        }
        /* hold this cycle: the previous move ended at rest, and a cycle
           at rest between moves keeps the sampled acceleration within
           the limits where the direction changes */
        tp.v = tp.a = 0;
        goto out;
    } else if (tc->probe_type >= 0 && tripped && !tp.aborting) {
        /* contact: record where we were when the input changed and stop */
        for (i = 0; i < NAX; i++)
            tp.probe_pos[i] = tp.pos[i];
        tp.probe_result = 1;
        tp.aborting = 1;
    }

    /* velocity for this cycle */
    left = tc->len - tp.s;
    vt = want_vel(tc);
    nv = tp.v + tc->amax * dt;
    if (vt < nv)
        nv = vt;
    if (nv < tp.v - tc->amax * dt)
        nv = tp.v - tc->amax * dt;
    vs = stop_vel(left, tc->amax, dt);
    if (nv > vs)
        nv = vs;
    if (nv < 0)
        nv = 0;
    if (left - nv * dt <= EPS * (1 + tc->len)) {
        nv = left / dt;
        tp.s = tc->len;
        finished = 1;
    } else {
        tp.s += nv * dt;
    }
    tp.a = (nv - tp.v) / dt;
    tp.v = nv;
    tc_eval(tc, tp.s, tp.pos);

    if (finished) {
        if (tc->probe_type >= 0 && tp.probe_result == 0) {
            tp.probe_result = -1;
            if (!(tc->probe_type & TP_PROBE_NO_ERROR)) {
                set_error("the probe move ended without contact");
                tp.aborting = 1;
            }
        }
        pop_tc();
        tp.v = 0;
        if (tp.stepping) {
            tp.stepping = 0;
            tp.pausing = 1;
        }
        if (tp.aborting)
            flush_queue();
    } else if (tp.aborting && tp.v == 0) {
        flush_queue();
    }
    goto out;

stopped:
    tp.v = tp.a = 0;
    if (tp.aborting)
        flush_queue();
out:
    for (i = 0; i < NAX; i++)
        tp.last_vel[i] = (tp.pos[i] - prev[i]) / (dt > 0 ? dt : 1);
    if (out)
        to_pose(tp.pos, out);
}

static double tp_distance_to_go(void)
{
    if (tp.count == 0)
        return 0;
    return tp.q[tp.head].len - tp.s;
}

static void tp_get_state(tp_state_t *st)
{
    double d[NAX];
    int i;

    memset(st, 0, sizeof(*st));
    st->vel = tp.v;
    st->acc = tp.a;
    st->dtg = tp_distance_to_go();
    for (i = 0; i < NAX; i++)
        d[i] = tp.count ? tp.q[tp.head].end[i] - tp.pos[i] : 0;
    to_pose(d, &st->dtg_pose);
    to_pose(tp.last_vel, &st->vel_pose);
    st->exec_id = tp.exec_id;
    st->motion_type = tp.count ? tp.q[tp.head].m.type : 0;
    st->queue_depth = tp.count;
    st->done = tp.count == 0 && tp.v == 0;
    st->paused = tp.pausing && tp.v == 0;
    st->probing = tp.count > 0 && tp.started &&
        tp.q[tp.head].probe_type >= 0;
}

static int tp_is_done(void)
{
    return tp.count == 0 && tp.v == 0;
}

static int tp_queue_depth(void)
{
    return tp.count;
}

static int tp_queue_space(void)
{
    return queue_size - tp.count;
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
    tp.q = hal_malloc((long)queue_size * sizeof(tc_t));
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
