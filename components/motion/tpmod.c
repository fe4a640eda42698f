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
 * (distance = pitch x revs since the start); they start and end at rest.
 */

#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_math.h"
#include "rtapi_string.h"
#include "hal.h"
#include "tp.h"
#include "tp_jerk.h"

MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("Blending look-ahead trajectory planner for motmod");
MODULE_LICENSE("GPL");

static char *tp_parms = "";
RTAPI_MP_STRING(tp_parms, "accepted for compatibility, not used");
static int queue_size = 2000;
RTAPI_MP_INT(queue_size, "number of moves the queue holds (200..1000000)");

#define NAX 9                   /* X Y Z A B C U V W */
#define EPS 1e-12               /* shorter than this: no motion */
#define NSYNC 256               /* pending synchronized outputs */
#define CAM_PTS 8               /* vertices one merged line remembers */
#define MAX_WALK 300            /* segments looked at per cycle, at most */
#define MAX_BACK 500            /* segments the backward pass updates per
                                   queued move, at most (earlier ones keep
                                   a lower, safe value until later moves
                                   reach them) */
#define PLAN_MARGIN 0.9         /* acceleration share of the backward pass */
#define BIG 1e30
#define BLEND_SHARE 0.8        /* centripetal share of a blend arc's
                                   acceleration (its speed hardly changes) */

enum { TC_LINE, TC_CIRCLE };

enum {                          /* rigid tap phases */
    RT_TAPPING, RT_REVERSING, RT_RETRACTING, RT_FINAL, RT_PLACING
};

typedef struct {
    int kind;                   /* TC_LINE or TC_CIRCLE */
    tp_move_t m;
    int probe_type;             /* TP_PROBE_* bits; -1: not a probe */
    int rigid;                  /* a rigid tap */
    int blend;                  /* a blend arc inserted by the planner */
    unsigned long seq;          /* the programmed move it belongs to */
    double start[NAX], end[NAX];
    double len;                 /* path length (parameter s: 0..len) */
    double vmax;                /* velocity limit from move, geometry, axes */
    double amax;                /* tangential acceleration limit */
    double aplan;               /* amax, halved next to a corner */
    double anb;                 /* the lowest amax of its neighbours */
    double afull, vc, share;    /* arc: tangential limit with no
                                   centripetal part, the centripetal speed
                                   limit, its share (see a_up) */
    double cap;                 /* velocity limit at the junction to the
                                   next segment (0: stop) */
    double vend;                /* planned velocity limit at the end */
    int corner_in, corner_out;  /* a direction/curvature change at the
                                   start / end */
    double orig_len;            /* before blend trimming */
    int trimmed_in, trimmed_out;
    int npts;
    union {                     /* (anonymous: C11) */
        struct {
            /* line: unit direction per axis (d p_i / d s) */
            double u[NAX];
            double orig_start[3];   /* before blend trimming */
            /* naive CAM merging: the vertices this line stands for */
            double pts[CAM_PTS][3];
        };
        struct {
            /* circle: center, unit normal, unit start direction cu,
               cw = n x cu */
            double c[3], n[3], cu[3], cw[3];
            double r0, r1, h0, h1, angle;
        };
    };
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

    /* inputs of this cycle */
    double in_feed;             /* feed scale x adaptive feed */
    int in_hold, in_inhibit;
    tp_inputs_t in;

    tc_t *q;                    /* ring of nslots segments (hal_malloc) */
    int nslots;
    int head, count;            /* segments */
    double qlen;                /* their total path length */
    int back_slot;              /* the backward pass goes on here (-1) */
    int moves;                  /* programmed moves queued */
    unsigned long next_seq;
    int started;                /* the head segment has started */
    double s, v, a;             /* progress along the head segment */
    double ja;                  /* path acceleration of a jerk-limited
                                   move (its state) */
    double reqv;

    double pos[NAX];            /* commanded position */
    double last_vel[NAX];
    int aborting, pausing, stepping;
    int corner_prev, corner_now; /* a cycle passing a junction */
    double a_after;             /* the acceleration it allowed */
    double a_after_up;          /* (speeding up) */
    unsigned long step_seq;     /* stepping: pause at the end of this move */
    int step_new;               /* step_seq not decided yet */
    int resume_after_step;      /* RESUME came while stopping for a step */
    int exec_id, motion_type;
    int active;

    /* synchronized moves */
    int waiting;                /* 1 at-speed, 2 index */
    int sync_started;
    double revs0;
    int rt_phase;
    double rt_smin, rt_smax;
    int rt_reversed;
    int rt_spindle;

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

static void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double dmin(double a, double b)
{
    return a < b ? a : b;
}

static double dmax(double a, double b)
{
    return a > b ? a : b;
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

static int slot(int k)          /* the k-th queued segment */
{
    return (tp.head + k) % tp.nslots;
}

static tc_t *seg(int k)
{
    return &tp.q[slot(k)];
}

static tc_t *tail(void)
{
    return tp.count ? seg(tp.count - 1) : NULL;
}

/* where the next queued move starts */
static const double *queue_end(void)
{
    tc_t *t = tail();
    if (!t)
        return tp.pos;
    return t->rigid ? t->start : t->end;
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
    if (!(isfinite(m->cam_tolerance) && m->cam_tolerance >= 0))
        return why_(why, whylen, -EINVAL,
                    "naive CAM tolerance must be zero or positive (got %g)",
                    m->cam_tolerance);
    if (m->sync < TP_SYNC_NONE || m->sync > TP_SYNC_VELOCITY)
        return why_(why, whylen, -EINVAL, "unknown synchronization %d",
                    m->sync);
    if (m->sync != TP_SYNC_NONE) {
        if (m->spindle < 0 || m->spindle >= TP_MAX_SPINDLES)
            return why_(why, whylen, -EINVAL,
                        "spindle %d does not exist (0..%d)", m->spindle,
                        TP_MAX_SPINDLES - 1);
        if (!(isfinite(m->pitch) && m->pitch > 0))
            return why_(why, whylen, -EINVAL,
                        "a synchronized move needs a positive pitch "
                        "(got %g)", m->pitch);
    }
    return 0;
}

static int check_room(int need, char *why, int whylen)
{
    if (!tp.inited)
        return why_(why, whylen, -ENODEV,
                    "the trajectory planner is not initialized");
    if (tp.aborting)
        return why_(why, whylen, -EBUSY,
                    "the trajectory planner is aborting");
    if (tp.moves >= queue_size || tp.count + need > tp.nslots)
        return why_(why, whylen, -ENOSPC,
                    "the motion queue is full (%d moves)", queue_size);
    return 0;
}

/* ------------------------------------------------------------ the limits */

/* a line: every axis moves u_i per unit of s */
static void line_limits(tc_t *tc)
{
    int i;
    tc->vmax = tc->m.ini_maxvel;
    tc->amax = tc->m.acc;
    for (i = 0; i < NAX; i++) {
        double f = fabs(tc->u[i]);
        if (f < EPS)
            continue;
        if (tp.ax_vel[i] > 0 && tp.ax_vel[i] / f < tc->vmax)
            tc->vmax = tp.ax_vel[i] / f;
        if (tp.ax_acc[i] > 0 && tp.ax_acc[i] / f < tc->amax)
            tc->amax = tp.ax_acc[i] / f;
    }
}

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
    for (i = 0; i < NAX; i++)
        tc->u[i] = tc->len > 0 ? d[i] / tc->len : 0;
    line_limits(tc);
}

static void line_eval(const tc_t *tc, double s, double *p)
{
    int i;
    for (i = 0; i < NAX; i++)
        p[i] = tc->start[i] + tc->u[i] * s;
}

/* limits of a circle/helix/spiral (see the top); share: the part of the
   acceleration left to the centripetal one (the rest is tangential) */
static void circle_limits(tc_t *tc, double share)
{
    double rmax = dmax(tc->r0, tc->r1);
    double k = tc->angle / tc->len;         /* d phase / d s */
    double dr = fabs(tc->r1 - tc->r0) / tc->angle;
    double dh = fabs(tc->h1 - tc->h0) / tc->angle;
    double curv, v;
    int i;

    tc->vmax = tc->m.ini_maxvel;
    tc->amax = (1 - share) * tc->m.acc;
    tc->afull = tc->m.acc;
    tc->vc = BIG;
    tc->share = share;
    /* the path: |d2p/ds2| <= k^2 (rmax + 2 dr) */
    curv = k * k * (rmax + 2 * dr);
    if (curv > 0) {
        v = sqrt(share * tc->m.acc / curv);
        tc->vmax = dmin(tc->vmax, v);
        tc->vc = dmin(tc->vc, v);
    }
    for (i = 0; i < 3; i++) {
        double m = sqrt(tc->cu[i] * tc->cu[i] + tc->cw[i] * tc->cw[i]);
        double ti = k * ((rmax + dr) * m + dh * fabs(tc->n[i]));
        double ci = k * k * (rmax + 2 * dr) * m;
        if (ti < EPS && ci < EPS)
            continue;
        if (tp.ax_vel[i] > 0 && ti > EPS)
            tc->vmax = dmin(tc->vmax, tp.ax_vel[i] / ti);
        if (tp.ax_acc[i] > 0) {
            if (ti > EPS) {
                tc->amax = dmin(tc->amax, (1 - share) * tp.ax_acc[i] / ti);
                tc->afull = dmin(tc->afull, tp.ax_acc[i] / ti);
            }
            if (ci > EPS) {
                v = sqrt(share * tp.ax_acc[i] / ci);
                tc->vmax = dmin(tc->vmax, v);
                tc->vc = dmin(tc->vc, v);
            }
        }
    }
    for (i = 3; i < NAX; i++) {
        double f = fabs(tc->end[i] - tc->start[i]) / tc->len;
        if (f < EPS)
            continue;
        if (tp.ax_vel[i] > 0)
            tc->vmax = dmin(tc->vmax, tp.ax_vel[i] / f);
        if (tp.ax_acc[i] > 0) {
            tc->amax = dmin(tc->amax, tp.ax_acc[i] / f);
            tc->afull = dmin(tc->afull, tp.ax_acc[i] / f);
        }
    }
}

/* the acceleration segment t allows for speeding up to v: on an arc the
   centripetal part at v is share (v / vc)^2 of each axis's limit at most,
   the rest is free for the tangential part (decelerations keep aplan, which
   the look-ahead plans with) */
static double a_up(const tc_t *t, double v)
{
    double f;
    if (t->kind != TC_CIRCLE || t->corner_in || t->corner_out ||
        !(t->vc > 0) || t->vc >= BIG)
        return t->aplan;
    f = v / t->vc;
    f = f * f;
    if (f > 1)
        f = 1;
    return dmax(t->aplan, t->afull * (1 - t->share * f));
}

static int circle_setup(tc_t *tc, const PmCartesian *center,
                        const PmCartesian *normal, int turn,
                        char *why, int whylen)
{
    double r0v[3], r1v[3], e[3];
    double nn, ang, rmax, dh;
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
        tc->cu[i] = r0v[i] / tc->r0;
    cross3(tc->n, tc->cu, tc->cw);
    for (i = 0; i < 3; i++)
        e[i] = r1v[i] / tc->r1;
    ang = atan2(dot3(e, tc->cw), dot3(e, tc->cu));
    if (ang <= 1e-12)
        ang += 2 * M_PI;
    tc->angle = ang + 2 * M_PI * turn;
    /* length: the helix on the larger radius (the speed along the path is
       then never above the planned one, also on a spiral) */
    rmax = dmax(tc->r0, tc->r1);
    dh = tc->h1 - tc->h0;
    tc->len = sqrt(rmax * tc->angle * rmax * tc->angle + dh * dh);
    circle_limits(tc, 0.5);
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
        p[i] = tc->c[i] + r * (cs * tc->cu[i] + sn * tc->cw[i]) +
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

/* the unit tangent (d p / d s, per axis) at the start (end = 0) or end */
static void tc_tangent(const tc_t *tc, int at_end, double *t)
{
    int i;
    if (tc->kind == TC_LINE) {
        for (i = 0; i < NAX; i++)
            t[i] = tc->u[i];
        return;
    } else {
        double ph = at_end ? tc->angle : 0;
        double r = at_end ? tc->r1 : tc->r0;
        double k = tc->angle / tc->len;
        double dr = (tc->r1 - tc->r0) / tc->angle;
        double dh = (tc->h1 - tc->h0) / tc->angle;
        double cs = cos(ph), sn = sin(ph);
        for (i = 0; i < 3; i++)
            t[i] = k * (r * (-sn * tc->cu[i] + cs * tc->cw[i]) +
                        dr * (cs * tc->cu[i] + sn * tc->cw[i]) +
                        dh * tc->n[i]);
        for (i = 3; i < NAX; i++)
            t[i] = (tc->end[i] - tc->start[i]) / tc->len;
    }
}

/* ------------------------------------------------------------ look-ahead */

/* the highest velocity v for this cycle after which the rest d of the
   path can still be covered stopping in whole cycles with decelerations
   of at most acc (v, v - acc*dt, v - 2*acc*dt, ... sum to d / dt) */
static double stop_vel(double d, double acc, double dt)
{
    double D, k, frac;

    if (d <= 0)
        return 0;
    D = d / (acc * dt * dt);
    if (D > 1e15)
        return sqrt(2 * d * acc) - 0.5 * acc * dt;
    k = floor((sqrt(1 + 8 * D) - 1) / 2);
    while (k > 0 && k * (k + 1) / 2 > D)
        k--;
    while ((k + 1) * (k + 2) / 2 <= D)
        k++;
    frac = (D - k * (k + 1) / 2) / (k + 1);
    return (k + frac) * acc * dt;
}

/* the highest velocity w for this cycle such that, decelerating by at most
   acc*dt per cycle, no cycle faster than vf passes the junction d ahead:
   with n cycles faster than vf, w <= vf + n A and their distance
   n w - A n (n - 1) / 2 <= d / dt (A = acc dt) */
static double junction_vel(double d, double vf, double acc, double dt)
{
    double A = acc * dt, D, b, n0, best;
    long n, n1;

    if (vf <= 0)
        return stop_vel(d, acc, dt);
    /* a cycle that ends exactly on the junction counts as passing it (the
       direction changes between it and the next one): keep 1 nm short */
    d -= 1e-9;
    if (d <= 0)
        return vf;
    D = d / dt;
    b = vf + 0.5 * A;
    n0 = (-b + sqrt(b * b + 2 * A * D)) / A;
    if (n0 > 1e9)
        return sqrt(vf * vf + 2 * acc * d) - A;
    best = vf;
    n1 = (long)floor(n0);
    for (n = n1 - 1; n <= n1 + 1; n++) {
        double w;
        if (n < 1)
            continue;
        w = dmin(vf + n * A, D / n + A * (n - 1) * 0.5);
        if (w > best)
            best = w;
    }
    return best;
}

/* the junction cap between a and b (a's end, b's start): 0 for a stop;
   else the exact-path rule (top of the file); corner flags set */
static double exact_cap(tc_t *a, tc_t *b)
{
    double ta[NAX], tb[NAX], cap = BIG, dn = 0;
    int i;

    tc_tangent(a, 1, ta);
    tc_tangent(b, 0, tb);
    for (i = 0; i < NAX; i++) {
        double du = fabs(tb[i] - ta[i]);
        dn += du * du;
        if (du > 1e-12 && tp.ax_acc[i] > 0)
            cap = dmin(cap, 0.5 * tp.ax_acc[i] * tp.dt / du);
    }
    dn = sqrt(dn);
    if (dn > 1e-12)
        cap = dmin(cap, 0.5 * dmin(a->m.acc, b->m.acc) * tp.dt / dn);
    return cap;
}

static int is_stop_type(const tc_t *t)
{
    return t->probe_type >= 0 || t->rigid || t->m.sync != TP_SYNC_NONE;
}

/* set a's cap and the corner flags of the junction a -> b */
static void link_nb(tc_t *a, tc_t *b)
{
    a->anb = dmin(a->anb, b->amax);
    b->anb = dmin(b->anb, a->amax);
}

static void junction_setup(tc_t *a, tc_t *b)
{
    double ta[NAX], tb[NAX], dn = 0;
    int i, corner;

    link_nb(a, b);
    if (a->m.term_cond == TP_TERM_STOP || is_stop_type(a) ||
        is_stop_type(b) || a->len <= 0 || b->len <= 0) {
        a->cap = 0;
        a->corner_out = b->corner_in = 0;
        return;
    }
    tc_tangent(a, 1, ta);
    tc_tangent(b, 0, tb);
    for (i = 0; i < NAX; i++)
        dn += (tb[i] - ta[i]) * (tb[i] - ta[i]);
    /* (a tangent junction into or out of an arc changes the curvature
       only: the arc's own limits keep its centripetal part) */
    corner = dn > 1e-24;
    a->cap = exact_cap(a, b);
    a->corner_out = b->corner_in = corner;
    /* jerk-limited moves: a change of direction or curvature would be a
       step in acceleration: stop there */
    if ((corner || a->kind == TC_CIRCLE || b->kind == TC_CIRCLE) &&
        (a->m.jerk > 0 || b->m.jerk > 0)) {
        a->cap = 0;
        a->corner_out = b->corner_in = 0;
    }
    /* a corner that must be passed within a couple of acceleration steps
       of rest: stop there (an exact stop is as fast, and at rest) */
    if (corner && a->cap < 2 * dmin(a->amax, b->amax) * tp.dt) {
        a->cap = 0;
        a->corner_out = b->corner_in = 0;
    }
}

/* the acceleration the look-ahead plans with: the full one, but half on
   short segments next to a corner, where every cycle may pass one (see
   run_planned) */
static void set_aplan(tc_t *t)
{
    double vm = dmin(t->vmax, t->m.ini_maxvel);
    int near = t->len < 4 * vm * tp.dt + 1e-9;
    t->aplan = ((t->corner_in || t->corner_out) && near)
        ? 0.5 * t->amax : t->amax;
}

static double plan_vmax(const tc_t *t)
{
    double v = t->vmax;
    if (tp.vel_limit > 0 && tp.vel_limit < v)
        v = tp.vel_limit;
    return v;
}

/* the highest velocity at the start of segment b from which its end can
   be reached at v (continuous, with a margin on the acceleration; less one
   step on a long segment: the cycle after passing a junction may be held
   to the lower acceleration of the segments it touched) */
static double reach_vel(const tc_t *b, double v)
{
    double a = b->aplan, r;
    /* a short segment next to a corner is passed in cycles that also
       touch its neighbours: plan it with their acceleration too */
    if (a < b->amax)
        a = dmin(a, 0.5 * b->anb);
    /* so is any segment shorter than a few cycles of travel: the cycles
       after passing into it may be held to its neighbour's acceleration */
    if (b->len < 4 * dmin(b->vmax, b->m.ini_maxvel) * tp.dt + 1e-9)
        a = dmin(a, b->anb);
    r = sqrt(v * v + 2 * PLAN_MARGIN * a * b->len);
    if (b->aplan >= b->amax)
        r = dmax(v, r - b->aplan * tp.dt);
    return r;
}

/* the backward pass from the tail: vend of every segment before it, until
   a value no longer changes (at least `force` segments are recomputed) */
static int back_from(int k, int force, int *budget)
{
    int n = 0;
    for (; k >= 0; k--, n++) {
        tc_t *a = seg(k), *b = seg(k + 1);
        double v = dmin(a->cap, dmin(plan_vmax(a), plan_vmax(b)));
        double r = reach_vel(b, b->vend);
        if (a->cap <= 0)
            v = 0;
        if (r < v)
            v = r;
        if (n >= force && v == a->vend)
            return -1;
        if (--*budget < 0)
            return k;               /* not done: k next */
        a->vend = v;
    }
    return -1;
}

/* (the work per queued move is bounded by MAX_BACK; where a pass had to
   stop, the next passes go on from there) */
static void backward_pass(int force)
{
    int budget = MAX_BACK, k;
    if (tp.count == 0)
        return;
    seg(tp.count - 1)->vend = 0;
    k = back_from(tp.count - 2, force, &budget);
    if (k >= 0) {
        tp.back_slot = slot(k);
        return;
    }
    if (tp.back_slot >= 0) {
        k = (tp.back_slot - tp.head + tp.nslots) % tp.nslots;
        tp.back_slot = -1;
        if (k < tp.count - 1 && budget > 0) {
            k = back_from(k, 1, &budget);
            if (k >= 0)
                tp.back_slot = slot(k);
        }
    }
}

/* ----------------------------------------------------------------- queue */

static tc_t *new_tc(const tp_move_t *m, int kind, const EmcPose *end)
{
    tc_t *tc = &tp.q[slot(tp.count)];
    const double *st = queue_end();
    int i;

    memset(tc, 0, sizeof(*tc));
    tc->kind = kind;
    tc->m = *m;
    tc->probe_type = -1;
    for (i = 0; i < NAX; i++)
        tc->start[i] = st[i];
    pose_to(end, tc->end);
    tc->seq = tp.next_seq;
    tc->anb = BIG;
    return tc;
}

/* distance from the present position to the start of queued segment k */
static double dist_to(int k)
{
    double d = 0;
    int j;
    if (k == 0)
        return 0;
    d = seg(0)->len - tp.s;
    for (j = 1; j < k && d < 1e300; j++)
        d += seg(j)->len;
    return d;
}

/* may segment k (ahead) be changed (shortened) without breaking the
   velocity profile the planner may be following now? */
static int can_change(int k, double new_len)
{
    double v = tp.v, a, need;
    tc_t *t = seg(k);
    if (k == 0 && tp.started && tp.s >= new_len)
        return 0;
    if (v <= 0)
        return 1;
    a = dmax(t->aplan * 0.5, 1e-9);
    need = v * v / (2 * a) + 4 * v * tp.dt;
    if (k == 0)
        return new_len - tp.s > need;
    if (k == tp.count - 1)          /* the tail: from the running total */
        return tp.qlen - tp.s - t->len > need;
    return dist_to(k) > need;
}

static int xyz_only_line(const tc_t *t)
{
    int i;
    if (t->kind != TC_LINE || t->probe_type >= 0 || t->rigid ||
        t->m.sync != TP_SYNC_NONE || t->blend)
        return 0;
    for (i = 3; i < NAX; i++)
        if (fabs(t->end[i] - t->start[i]) > EPS)
            return 0;
    return t->len > EPS;
}

/* try to round the corner between the last two segments (lines a, b) with
   a tangent arc; b is not queued yet (it is at slot count) */
static int insert_blend(tc_t *a, tc_t *b)
{
    double c1 = dot3(a->u, b->u), alpha, half, d, R, tol, nv[3], pc[3];
    double nrm[3], nn, e0[3];
    tc_t *arc, tmp;
    int i, ka = tp.count - 1;

    if (a->m.term_cond != TP_TERM_BLEND || !xyz_only_line(a) ||
        !xyz_only_line(b) || a->trimmed_out || a->m.jerk > 0 ||
        b->m.jerk > 0)
        return 0;
    if (c1 > 1)
        c1 = 1;
    if (c1 < -1)
        c1 = -1;
    alpha = acos(c1);
    if (alpha < 1e-9 || alpha > M_PI - 1e-6)
        return 0;
    /* not needed when the exact-path corner is fast enough */
    if (exact_cap(a, b) >= dmin(plan_vmax(a), plan_vmax(b)))
        return 0;
    half = 0.5 * alpha;
    d = 0.5 * (1 - 1e-6) * dmin(a->orig_len, b->orig_len);
    tol = a->m.tolerance;
    if (tol > 0) {
        /* the arc's middle is R (1 - cos(t/2)) from both lines */
        double rt = tol / (1 - cos(half));
        d = dmin(d, rt * tan(half));
    }
    if (d < 1e-9 || d >= a->len - 1e-12)
        return 0;
    R = d / tan(half);
    if (!can_change(ka, a->len - d))
        return 0;
    /* the arc: from a's end minus d to b's start plus d; center inward */
    for (i = 0; i < 3; i++)
        pc[i] = a->end[i];              /* the corner */
    for (i = 0; i < 3; i++)
        nrm[i] = b->u[i] - c1 * a->u[i];
    nn = norm3(nrm);
    if (nn < 1e-12)
        return 0;
    for (i = 0; i < 3; i++)
        nrm[i] /= nn;
    tmp = *b;                           /* b moves one slot on */
    arc = b;
    memset(arc, 0, sizeof(*arc));
    arc->kind = TC_CIRCLE;
    arc->m = tmp.m;
    arc->probe_type = -1;
    arc->blend = 1;
    arc->seq = tmp.seq;
    for (i = 0; i < NAX; i++) {
        arc->start[i] = a->end[i];
        arc->end[i] = a->end[i];
    }
    for (i = 0; i < 3; i++) {
        arc->start[i] = pc[i] - d * a->u[i];
        arc->end[i] = pc[i] + d * tmp.u[i];
        arc->c[i] = arc->start[i] + R * nrm[i];
        e0[i] = -nrm[i];
        arc->cu[i] = e0[i];
    }
    cross3(a->u, tmp.u, nv);
    nn = norm3(nv);
    for (i = 0; i < 3; i++)
        arc->n[i] = nv[i] / nn;
    cross3(arc->n, arc->cu, arc->cw);
    arc->r0 = arc->r1 = R;
    arc->h0 = arc->h1 = 0;
    arc->angle = alpha;
    arc->len = R * alpha;
    circle_limits(arc, BLEND_SHARE);
    /* the arc is at most as fast as either line's move allows */
    arc->vmax = dmin(arc->vmax, dmax(a->vmax, tmp.vmax));
    /* trim a */
    for (i = 0; i < 3; i++)
        a->end[i] = arc->start[i];
    a->len -= d;
    tp.qlen -= d;
    a->trimmed_out = 1;
    /* b one slot on, trimmed */
    {
        tc_t *nb = &tp.q[slot(tp.count + 1)];
        *nb = tmp;
        for (i = 0; i < 3; i++)
            nb->start[i] = arc->end[i];
        nb->len -= d;
        nb->trimmed_in = 1;
        a->cap = BIG;
        arc->cap = BIG;
        arc->anb = nb->anb = BIG;
        link_nb(a, arc);
        link_nb(arc, nb);
        /* tangent: no corner (the arc's limits keep its centripetal
           acceleration) */
        a->corner_out = arc->corner_in = 0;
        arc->corner_out = nb->corner_in = 0;
    }
    return 1;
}

/* may line b be merged into the tail line t (naive CAM, G64 Q)? */
static int try_merge(tc_t *t, const double *end, const tp_move_t *m)
{
    double q = m->cam_tolerance, d[3], L, nd[3];
    int i, k;

    if (q <= 0 || m->term_cond != TP_TERM_BLEND ||
        t->m.term_cond != TP_TERM_BLEND || !xyz_only_line(t) ||
        t->trimmed_out || t->npts >= CAM_PTS || tp.count < 1)
        return 0;
    if (t->m.type != m->type || t->m.vel != m->vel ||
        t->m.acc != m->acc || t->m.ini_maxvel != m->ini_maxvel ||
        t->m.flags != m->flags || t->m.cam_tolerance != q)
        return 0;
    if (tp.count == 1 && tp.started)
        return 0;
    for (i = 3; i < NAX; i++)
        if (fabs(end[i] - t->end[i]) > EPS)
            return 0;
    /* a synchronized output waits for the start of the new move */
    if (tp.ev_count > 0 &&
        tp.ev[(tp.ev_head + tp.ev_count - 1) % NSYNC].seq == tp.next_seq)
        return 0;
    /* the merged line: from t's (untrimmed) start to end */
    for (i = 0; i < 3; i++)
        d[i] = end[i] - t->orig_start[i];
    L = norm3(d);
    if (L < EPS)
        return 0;
    for (i = 0; i < 3; i++)
        nd[i] = d[i] / L;
    /* every vertex (t's end and the earlier ones) within q of it */
    for (k = 0; k <= t->npts; k++) {
        const double *p = k < t->npts ? t->pts[k] : t->end;
        double r[3], h, dd;
        for (i = 0; i < 3; i++)
            r[i] = p[i] - t->orig_start[i];
        h = dot3(r, nd);
        if (h < 0 || h > L)
            return 0;
        dd = dot3(r, r) - h * h;
        if (dd > q * q)
            return 0;
    }
    /* the merged line must point the same way as t at its start when t
       was blended in (the blend is tangent to t's old direction) */
    if (t->trimmed_in) {
        double c = dot3(nd, t->u);
        if (c < 1 - 1e-12)
            return 0;
    }
    return 1;
}

static void commit_move(void)
{
    tp.next_seq++;
    tp.moves++;
}

/* queue a line (also probes and rigid taps, kind set by the caller) */
static int queue_line(const EmcPose *end, const tp_move_t *m, int probe_type,
                      int rigid, char *why, int whylen)
{
    tc_t *tc, *t;
    double e[NAX];
    int r, i;

    if ((r = check_room(2, why, whylen)) < 0)
        return r;
    if ((r = check_move(m, why, whylen)) < 0)
        return r;
    if (!end || !finite_pose(end))
        return why_(why, whylen, -EINVAL,
                    "the end point is not a finite number in every axis");
    pose_to(end, e);
    t = tail();
    if (t && probe_type < 0 && !rigid && m->sync == TP_SYNC_NONE &&
        t->kind == TC_LINE && try_merge(t, e, m)) {
        int k = tp.count - 1;
        double nl;
        double d3[3];
        for (i = 0; i < 3; i++)
            d3[i] = e[i] - t->start[i];
        nl = norm3(d3);
        if (can_change(k, nl)) {
            double old_len = t->len;
            for (i = 0; i < 3; i++)
                t->pts[t->npts][i] = t->end[i];
            t->npts++;
            for (i = 0; i < NAX; i++)
                t->end[i] = e[i];
            t->m.id = m->id;
            if (t->trimmed_in) {
                /* keep the direction (checked) and the blended start */
                t->len = nl;
                for (i = 0; i < 3; i++)
                    d3[i] = e[i] - t->orig_start[i];
                t->orig_len = norm3(d3);
            } else {
                line_setup(t);
                t->orig_len = t->len;
                if (tp.count >= 2)
                    junction_setup(seg(tp.count - 2), t);
            }
            set_aplan(t);
            if (tp.count >= 2)
                set_aplan(seg(tp.count - 2));
            tp.qlen += t->len - old_len;
            /* (t keeps its number; the new one is skipped) */
            tp.next_seq++;
            backward_pass(3);
            return 0;
        }
    }
    tc = new_tc(m, TC_LINE, end);
    if (probe_type >= 0) {
        tc->m.type = TP_MOTION_PROBING;
        tc->probe_type = probe_type;
    }
    tc->rigid = rigid;
    line_setup(tc);
    if (rigid && !(tc->len > 0))
        return why_(why, whylen, -EINVAL,
                    "a rigid tap needs a nonzero length");
    for (i = 0; i < 3; i++)
        tc->orig_start[i] = tc->start[i];
    tc->orig_len = tc->len;
    if (t && tc->len > 0) {
        /* t's end changes only when a blend is inserted */
        if (insert_blend(t, tc)) {
            tc_t *arc = &tp.q[slot(tp.count)];
            tc_t *nb = &tp.q[slot(tp.count + 1)];
            tp.count += 2;
            tp.qlen += arc->len + nb->len;
            set_aplan(t);
            set_aplan(arc);
            set_aplan(nb);
            nb->cap = 0;
            commit_move();
            backward_pass(4);
            return 0;
        }
        junction_setup(t, tc);
        set_aplan(t);
    }
    tc->cap = 0;
    set_aplan(tc);
    tp.count++;
    tp.qlen += tc->len;
    commit_move();
    backward_pass(3);
    return 0;
}

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
    tp.qlen = 0;
    tp.back_slot = -1;
    tp.moves = 0;
    tp.started = 0;
    tp.s = tp.v = tp.a = tp.ja = 0;
    tp.ev_head = tp.ev_count = 0;
    tp.aborting = 0;
    tp.pausing = 0;
    tp.stepping = 0;
    tp.resume_after_step = 0;
    tp.waiting = 0;
    tp.sync_started = 0;
    tp.corner_prev = tp.corner_now = 0;
    if (tp.rt_reversed && tp.hooks.spindle_reverse)
        tp.hooks.spindle_reverse(tp.rt_spindle, 0);
    tp.rt_reversed = 0;
}

/* the head segment is done */
static void pop_tc(void)
{
    tc_t *t = seg(0);
    int last_of_move = tp.count < 2 || seg(1)->seq != t->seq;
    tp.head = (tp.head + 1) % tp.nslots;
    tp.count--;
    tp.qlen = tp.count ? tp.qlen - t->len : 0;
    if (last_of_move && tp.moves > 0)
        tp.moves--;
    tp.started = 0;
    tp.s = 0;
    tp.sync_started = 0;
    tp.waiting = 0;
    if (tp.stepping && last_of_move && t->seq == tp.step_seq) {
        tp.stepping = 0;
        tp.pausing = !tp.resume_after_step;
        tp.resume_after_step = 0;
    }
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
    return queue_line(end, m, -1, 0, why, whylen);
}

static int tp_add_circle(const EmcPose *end, const PmCartesian *center,
                         const PmCartesian *normal, int turn,
                         const tp_move_t *m, char *why, int whylen)
{
    tc_t *tc, *t;
    int r;

    if ((r = check_room(1, why, whylen)) < 0)
        return r;
    if ((r = check_move(m, why, whylen)) < 0)
        return r;
    if (m->sync == TP_SYNC_POSITION)
        return why_(why, whylen, -EINVAL,
                    "a position-synchronized move must be a line");
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
    t = tail();
    tc = new_tc(m, TC_CIRCLE, end);
    if ((r = circle_setup(tc, center, normal, turn, why, whylen)) < 0)
        return r;
    tc->orig_len = tc->len;
    if (t) {
        junction_setup(t, tc);
        set_aplan(t);
    }
    tc->cap = 0;
    set_aplan(tc);
    tp.count++;
    tp.qlen += tc->len;
    commit_move();
    backward_pass(3);
    return 0;
}

static int tp_add_probe(const EmcPose *end, const tp_move_t *m,
                        int probe_type, char *why, int whylen)
{
    if (probe_type & ~(TP_PROBE_NO_ERROR | TP_PROBE_AWAY))
        return why_(why, whylen, -EINVAL, "unknown probe type %d",
                    probe_type);
    return queue_line(end, m, probe_type, 0, why, whylen);
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
    return queue_line(end, &mm, -1, 1, why, whylen);
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

static void tp_reset(void)
{
    int i;
    flush_queue();
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
    tp.step_seq = seg(0)->seq;
    tp.step_new = 1;
}

static void tp_set_scale(double feed, double rapid)
{
    tp.feed_scale = isfinite(feed) && feed > 0 ? feed : 0;
    tp.rapid_scale = isfinite(rapid) && rapid > 0 ? rapid : 0;
}

/* the velocity segment t asks for now; plain: without pause, abort, feed
   hold and feed inhibit (those only make the head decelerate) */
static double want_vel_(const tc_t *t, int plain)
{
    double v = t->m.vel;
    if (t->m.sync == TP_SYNC_VELOCITY) {
        double sp = (tp.in.have & TP_IN_SPINDLES)
            ? tp.in.spindle[t->m.spindle].speed : tp.in.spindle_speed;
        v = t->m.pitch * fabs(isfinite(sp) ? sp : 0);
    }
    if (!(t->m.flags & TP_MOVE_NO_FEED_SCALE))
        v *= t->m.type == TP_MOTION_TRAVERSE ? tp.rapid_scale : tp.in_feed;
    if (!plain && tp.in_inhibit)
        v = 0;
    if (!plain && tp.in_hold && !(t->m.flags & TP_MOVE_NO_FEED_HOLD))
        v = 0;
    if (v > t->vmax)
        v = t->vmax;
    if (t->m.ini_maxvel < v)
        v = t->m.ini_maxvel;
    if (tp.vel_limit > 0 && v > tp.vel_limit)
        v = tp.vel_limit;
    if (!plain && (tp.aborting || tp.pausing))
        v = 0;
    return v;
}

static double want_vel(const tc_t *t)
{
    return want_vel_(t, 0);
}

/* the junction at the end of segment k must be passed at rest */
static int stop_at_end(int k)
{
    tc_t *t = seg(k);
    if (k >= tp.count - 1 || t->cap <= 0)
        return 1;
    if (tp.stepping && t->seq == tp.step_seq && seg(k + 1)->seq != t->seq)
        return 1;
    return 0;
}

static void finish_probe(tc_t *tc)
{
    if (tc->probe_type >= 0 && tp.probe_result == 0) {
        tp.probe_result = -1;
        if (!(tc->probe_type & TP_PROBE_NO_ERROR)) {
            set_error("the probe move ended without contact");
            tp.aborting = 1;
        }
    }
}

static int start_tc(const tp_inputs_t *in)
{
    tc_t *tc = seg(0);
    tp.started = 1;
    tp.exec_id = tc->m.id;
    tp.motion_type = tc->m.type;
    fire_sync(tc->seq);
    if (tc->probe_type >= 0) {
        int tripped = in ? ((tc->probe_type & TP_PROBE_AWAY)
                            ? !in->probe_input : in->probe_input != 0) : 0;
        tp.probe_result = 0;
        if (tripped) {
            set_error("the probe is already tripped when the probe "
                      "move starts");
            flush_queue();
            return -1;
        }
    }
    return 0;
}

/* the junctions of one look-ahead walk */
static struct {
    double dist;                /* from here to the end of the segment */
    double vf;                  /* velocity limit at the junction */
    double ws;                  /* the next segment's requested velocity */
    int stop;
    int composed;               /* vf comes from later junctions */
} wk[MAX_WALK];

static double spindle_revs(int n)
{
    double r = (tp.in.have & TP_IN_SPINDLES) ? tp.in.spindle[n].revs
                                             : tp.in.spindle_revs;
    return isfinite(r) ? r : 0;
}

/* a position-synchronized move or rigid tap at the head; returns 1 while
   it is in charge of the cycle */
static int run_synced(tc_t *tc)
{
    int n = tc->m.spindle;
    double s_old = tp.s, s;

    if (!tp.sync_started) {
        int at_speed = (tp.in.have & TP_IN_SPINDLES)
            ? tp.in.spindle[n].at_speed : tp.in.spindle_at_speed;
        if (tp.aborting) {
            flush_queue();
            return 1;
        }
        if (tp.in_inhibit || tp.pausing) {
            tp.waiting = 0;
            return 1;
        }
        if (tp.waiting == 0) {
            tp.waiting = 1;
        }
        if (tp.waiting == 1) {
            if (!at_speed)
                return 1;
            if (tp.hooks.index_enable && (tp.in.have & TP_IN_SPINDLES)) {
                tp.hooks.index_enable(n);
                tp.waiting = 2;
                return 1;
            }
        } else if (tp.waiting == 2) {
            if (tp.in.spindle[n].index_enable)
                return 1;
        }
        tp.waiting = 0;
        tp.sync_started = 1;
        tp.revs0 = spindle_revs(n);
        tp.rt_phase = RT_TAPPING;
        tp.rt_smin = tp.rt_smax = 0;
        return 1;
    }
    s = tc->m.pitch * (spindle_revs(n) - tp.revs0);
    if (!tc->rigid) {
        /* G33: forward only, to the end */
        s = fabs(s);
        if (s >= tc->len) {
            tp.s = tc->len;
            tc_eval(tc, tp.s, tp.pos);
            tp.v = 0;
            pop_tc();
            return 1;
        }
        if (s < s_old)
            s = s_old;
        tp.s = s;
        tp.v = (s - s_old) / tp.dt;
        line_eval(tc, s, tp.pos);
        return 1;
    }
    switch (tp.rt_phase) {
    case RT_TAPPING:
        if (s >= tc->len) {
            tp.hooks.spindle_reverse(n, 1);
            tp.rt_reversed = 1;
            tp.rt_spindle = n;
            tp.rt_phase = RT_REVERSING;
            tp.rt_smax = s;
        }
        break;
    case RT_REVERSING:
        if (s > tp.rt_smax)
            tp.rt_smax = s;
        else if (s < tp.rt_smax - 1e-12)
            tp.rt_phase = RT_RETRACTING;
        break;
    case RT_RETRACTING:
        if (s <= 0) {
            tp.hooks.spindle_reverse(n, 0);
            tp.rt_reversed = 0;
            tp.rt_phase = RT_FINAL;
            tp.rt_smin = s;
        }
        break;
    case RT_FINAL:
        if (s < tp.rt_smin) {
            tp.rt_smin = s;
        } else if (s > tp.rt_smin + 1e-12) {
            tp.rt_phase = RT_PLACING;
            s = s_old;
            tp.v = 0;
        }
        break;
    default:
        break;
    }
    if (tp.rt_phase == RT_PLACING) {
        /* back to the start under the move's acceleration */
        double left = -s_old, nv;
        double dir = left > 0 ? 1 : -1;
        double a = tc->amax;
        left = fabs(left);
        nv = dmin(fabs(tp.v) + a * tp.dt, stop_vel(left, a, tp.dt));
        nv = dmin(nv, tc->vmax);
        if (left - nv * tp.dt <= 1e-12) {
            tp.s = 0;
            line_eval(tc, 0, tp.pos);
            tp.v = 0;
            tp.hooks.spindle_reverse(n, 0);
            pop_tc();
            return 1;
        }
        tp.s = s_old + dir * nv * tp.dt;
        tp.v = dir * nv;
        line_eval(tc, tp.s, tp.pos);
        return 1;
    }
    tp.s = s;
    tp.v = (s - s_old) / tp.dt;
    line_eval(tc, s, tp.pos);
    return 1;
}

/* one cycle of ordinary (planned) motion at the head */
static void run_planned(const tp_inputs_t *in)
{
    double dt = tp.dt, lim = BIG, lim_hard, dist, arun, acyc;
    double vt, nv, lo, hi, step, moved = 0;
    int k, tripped, nw = 0, step_tries = 0, step_probe = 0;
    double soft = BIG;
    tc_t *tc = seg(0);

    /* probing: contact stops the move and records the position of the
       cycle the input changed in */
    if (tc->probe_type >= 0 && in && !tp.aborting && tp.probe_result == 0) {
        tripped = (tc->probe_type & TP_PROBE_AWAY) ? !in->probe_input
                                                  : in->probe_input != 0;
        if (tripped) {
            memcpy(tp.probe_pos, tp.pos, sizeof(tp.probe_pos));
            tp.probe_result = 1;
            tp.aborting = 1;
        }
    }

    /* the acceleration of this cycle: the head's; after a cycle that
       passed a junction, the one that cycle had (see below) */
    acyc = tc->aplan;
    if (tp.corner_prev)
        acyc = dmin(acyc, tp.a_after);
    vt = want_vel(tc);
    tp.reqv = vt;
    {
        double au = a_up(tc, tp.v + a_up(tc, tp.v) * dt);
        if (tp.corner_prev)
            au = dmin(au, tp.a_after_up);
        hi = tp.v + dmax(acyc, au) * dt;
    }
    lo = tp.v - acyc * dt;
    nv = dmin(hi, vt);
    if (nv < lo)
        nv = lo;

    /* the junctions ahead, up to the stopping distance (at most MAX_WALK
       segments; vend covers what lies beyond).  Stepping: when the end of
       the move to step to can no longer be reached at rest within the
       acceleration, the step goes on to the end of the next move */
step_again:
    lim = BIG;
    soft = BIG;
    {
        double vhi = tp.v + acyc * dt, amin = tc->aplan, horizon;
        dist = tc->len - tp.s;
        tp.active = 1;
        for (k = 0; k < tp.count && k < MAX_WALK; k++) {
            tc_t *t = seg(k);
            int stop = stop_at_end(k);
            if (k > 0) {
                amin = dmin(amin, t->aplan);
                if (dist - t->len < nv * dt)
                    tp.active = k + 1;
            }
            wk[k].dist = dist;
            wk[k].stop = stop;
            wk[k].vf = stop ? 0 : dmin(t->vend, t->cap);
            wk[k].ws = stop ? 0 : want_vel_(seg(k + 1), 1);
            nw = k + 1;
            if (stop)
                break;
            horizon = 2 * vhi * dt + vhi * vhi / (2 * PLAN_MARGIN * amin);
            if (dist > horizon)
                break;
            dist += seg(k + 1)->len;
        }
        /* backward over the walked junctions: the velocity at junction
           k from its own limit and, with a margin on the acceleration,
           from those after it (continuous: it composes exactly; the
           discrete staircase toward the first one, below, stays under
           the continuous one by less than one step, which is taken off
           when the composed value binds) */
        wk[nw - 1].composed = 0;
        for (k = nw - 2; k >= 0; k--) {
            tc_t *b = seg(k + 1);
            double r = reach_vel(b, wk[k + 1].vf);
            wk[k].composed = 0;
            if (r < wk[k].vf) {
                wk[k].vf = r;
                wk[k].composed = 1;
            }
        }
        /* the limits on this cycle's velocity: the staircase toward
           the head's junction (whose velocity now includes what every
           later walked junction needs), and for the junctions this cycle
           may pass besides (short segments), that it passes none faster
           than its velocity */
        double amin_near = tc->aplan;
        for (k = 0; k < nw; k++) {
            tc_t *t = seg(k);
            double c, vf = wk[k].vf, ax, vh;
            arun = t->aplan;
            amin_near = k == 0 ? arun : dmin(amin_near, arun);
            if (k > 0 && wk[k - 1].dist > 2 * vhi * dt)
                break;
            if (wk[k].stop) {
                /* the head's end: land on it; a later one: this cycle
                   either stays short of it or lands on it slowly enough
                   to rest the next cycle (the staircase toward it is in
                   the head's junction velocity) */
                if (k == 0)
                    c = stop_vel(wk[k].dist, arun, dt);
                else if (wk[k].dist / dt <= arun * dt)
                    c = wk[k].dist / dt;
                else
                    c = (wk[k].dist - 1e-9) / dt;
                if (c < lim)
                    lim = c;
                break;
            }
            /* the cycle before the one that passes the junction is at
               most one passing step (ax dt) faster than the junction's
               velocity: no cycle faster than vh reaches the point one
               such cycle before the junction */
            ax = dmin(arun, seg(k + 1)->aplan);
            if (t->corner_out)
                ax = dmin(ax, 0.5 * dmin(t->amax, seg(k + 1)->amax));
            vh = vf + ax * dt;
            if (k == 0) {
                if (wk[k].composed)
                    vf = dmax(0, vf - arun * dt);
                c = junction_vel(wk[k].dist, vf, arun, dt);
                c = dmin(c, junction_vel(wk[k].dist - vh * dt, vh, arun,
                                         dt));
                /* soft: the next move's requested velocity (a lowered
                   scale) may be passed while still decelerating at the
                   limit */
                if (wk[k].ws < vf)
                    soft = dmin(soft, dmax(junction_vel(wk[k].dist,
                                                        wk[k].ws, arun, dt),
                                           lo));
            } else {
                c = dmax(vf, (wk[k].dist - 1e-9) / dt);
                c = dmin(c, dmax(vh, (wk[k].dist - vh * dt - 1e-9) / dt));
            }
            if (c < lim)
                lim = c;
        }
    }
    if (step_probe) {
        /* the walk without the step's stop: when that stop is the cause,
           the step goes on to the end of the next move; else it stays */
        tp.stepping = 1;
        step_probe = 0;
        if (lim >= lo - 1e-9 * (1 + tp.v)) {
            int j;
            for (j = 0; j < tp.count - 1 && j < MAX_WALK; j++)
                if ((long)(seg(j)->seq - tp.step_seq) > 0) {
                    tp.step_seq = seg(j)->seq;
                    break;
                }
        } else {
            step_tries = 99;
        }
        goto step_again;
    }
    /* the first cycle after STEP: can the machine still stop at the end
       of the move?  (at most a few moves on; a few walks, once) */
    if (tp.stepping && tp.step_new && lim < lo - 1e-9 * (1 + tp.v) &&
        step_tries++ < 6) {
        tp.stepping = 0;
        step_probe = 1;
        goto step_again;
    }
    /* the step's stop is decided in the first cycle after STEP, from then
       on the machine stops there like at any other stop */
    if (tp.stepping)
        tp.step_new = 0;
    lim_hard = lim;
    if (soft < lim)
        lim = soft;
    if (nv > lim)
        nv = lim;
    if (nv < 0)
        nv = 0;

    /* a cycle that passes junctions changes the path velocity by no more
       than every segment it touches allows, and by half that at a corner
       (the direction change takes the other half of each axis's
       acceleration); so does the cycle after it.  The walk above made
       sure that the cycle before is at most that step faster than the
       junction's velocity */
    tp.corner_now = 0;
    {
        double d2 = tc->len - tp.s, ax = tc->aplan, am = tc->amax;
        double axu = a_up(tc, nv);
        int corner = 0, crossed = 0;
        for (k = 0; k + 1 < tp.count && k < MAX_WALK && nv * dt >= d2; k++) {
            if (stop_at_end(k))
                break;
            crossed = 1;
            ax = dmin(ax, seg(k + 1)->aplan);
            axu = dmin(axu, a_up(seg(k + 1), nv));
            am = dmin(am, seg(k + 1)->amax);
            if (seg(k)->corner_out)
                corner = 1;
            d2 += seg(k + 1)->len;
        }
        if (crossed) {
            /* (aplan of a short segment next to a corner is half already) */
            if (corner) {
                ax = dmin(ax, 0.5 * am);
                axu = dmin(axu, 0.5 * am);
            }
            axu = dmax(axu, ax);
            {
                double h2 = tp.v + axu * dt, l2 = tp.v - ax * dt;
                if (nv > h2)
                    nv = h2;
                /* (a soft limit never asks for more than that) */
                if (nv < l2)
                    nv = dmin(l2, lim_hard);
            }
            tp.corner_now = 1;
            tp.a_after = ax;
            tp.a_after_up = axu;
        }
    }

    /* jerk-limited moves: the time-optimal jerk-limited profile toward the
       requested velocity and toward the next junctions (ruckig), the
       most restrictive; the staircase above when none is found */
    step = nv * dt;
    if (tc->m.jerk > 0) {
        double J = tc->m.jerk, A = tc->amax, bp = BIG, bv = 0, ba = 0;
        double p, v, a, vmx = dmax(vt, tp.v);
        int ok = 0;
        if (tp_jerk_step(0, 0, vt, tp.v, tp.ja, vmx + 1, A, J, dt,
                         &p, &v, &a) == 0) {
            bp = p;
            bv = v;
            ba = a;
            ok = 1;
        }
        for (k = 0; k < nw && k < 3; k++) {
            double vf = wk[k].stop ? 0 : dmin(wk[k].vf, vt);
            if (k > 0 && wk[k - 1].stop)
                break;
            if (tp_jerk_step(1, wk[k].dist, vf, tp.v, tp.ja,
                             dmax(vmx, vf), A, J, dt, &p, &v, &a) == 0
                && p < bp) {
                bp = p;
                bv = v;
                ba = a;
                ok = 1;
            }
            if (wk[k].stop)
                break;
        }
        if (ok && bp >= 0 && bv >= 0) {
            step = bp;
            nv = bv;
            tp.ja = ba;
            /* never past a stop the profiles did not look at */
            for (k = 0; k < nw; k++)
                if (wk[k].stop) {
                    if (step > wk[k].dist)
                        step = wk[k].dist;
                    break;
                }
        } else {
            tp.ja = (nv - tp.v) / dt;
        }
    } else {
        tp.ja = 0;
    }

    /* advance */
    for (;;) {
        double rem;
        tc = seg(0);
        rem = tc->len - tp.s;
        if (step < rem - (stop_at_end(0) ? EPS * (1 + tc->len) : 0)) {
            tp.s += step;
            moved += step;
            tc_eval(tc, tp.s, tp.pos);
            break;
        }
        if (stop_at_end(0)) {
            /* land exactly on the end and rest */
            moved += rem;
            tp.s = tc->len;
            tc_eval(tc, tp.s, tp.pos);
            finish_probe(tc);
            pop_tc();
            nv = 0;
            tp.ja = 0;
            if (tp.aborting)
                flush_queue();
            break;
        }
        step -= rem;
        moved += rem;
        pop_tc();
        if (tp.count == 0)
            break;
        start_tc(in);
        if (tp.count == 0)
            break;
    }
    tp.a = (nv - tp.v) / dt;
    tp.v = nv;
    tp.corner_prev = tp.corner_now;
    (void)moved;
    if (tp.aborting && tp.v == 0)
        flush_queue();
}

static void tp_run_cycle(const tp_inputs_t *in, EmcPose *out)
{
    double prev[NAX], dt = tp.dt;
    int i;
    tc_t *tc;

    for (i = 0; i < NAX; i++)
        prev[i] = tp.pos[i];
    if (in)
        tp.in = *in;
    else
        memset(&tp.in, 0, sizeof(tp.in));
    if (tp.in.have & TP_IN_FEED) {
        double af = tp.in.adaptive_feed;
        if (!(af >= 0))
            af = 0;
        if (af > 1)
            af = 1;
        tp.in_feed = tp.feed_scale * af;
        tp.in_hold = tp.in.feed_hold != 0;
        tp.in_inhibit = tp.in.feed_inhibit != 0;
    } else {
        tp.in_feed = tp.feed_scale;
        tp.in_hold = tp.in_inhibit = 0;
    }
    tp.reqv = 0;
    tp.active = 0;
    if (!tp.inited || tp.count == 0) {
        tp.v = tp.a = 0;
        tp.aborting = 0;
        goto out;
    }
    tc = seg(0);
    if (tc->m.sync == TP_SYNC_POSITION && !(tp.aborting && tp.v != 0 &&
                                           !tc->rigid)) {
        if (!tp.started) {
            if (tp.aborting) {
                flush_queue();
                goto out;
            }
            if (tp.pausing && !tp.stepping)
                goto out;
            if (start_tc(in) < 0)
                goto out;
        }
        tp.active = 1;
        run_synced(tc);
        goto out;
    }
    if (!tp.started) {
        if (tp.aborting || (tp.pausing && !tp.stepping)) {
            tp.v = tp.a = 0;
            if (tp.aborting)
                flush_queue();
            goto out;
        }
        if (start_tc(in) < 0)
            goto out;
        if (tp.v == 0) {
            /* rest this cycle: the previous move ended at rest, and a
               cycle at rest between moves keeps the sampled acceleration
               within the limits where the direction changes */
            tp.a = 0;
            goto out;
        }
    }
    run_planned(in);
out:
    for (i = 0; i < NAX; i++)
        tp.last_vel[i] = (tp.pos[i] - prev[i]) / (dt > 0 ? dt : 1);
    if (out)
        to_pose(tp.pos, out);
}

static double tp_distance_to_go(void)
{
    double d;
    int k;
    if (tp.count == 0)
        return 0;
    d = seg(0)->len - tp.s;
    for (k = 1; k < tp.count && k < 4 && seg(k)->seq == seg(0)->seq; k++)
        d += seg(k)->len;
    if (seg(0)->rigid)
        d = fabs(seg(0)->len - tp.s);
    return d;
}

static void tp_get_state(tp_state_t *st)
{
    double d[NAX];
    int i, k;
    tc_t *t = tp.count ? seg(0) : NULL;

    memset(st, 0, sizeof(*st));
    st->vel = tp.v;
    st->acc = tp.a;
    st->dtg = tp_distance_to_go();
    if (t) {
        for (k = 0; k + 1 < tp.count && k < 4 &&
             seg(k + 1)->seq == t->seq; k++)
            ;
        for (i = 0; i < NAX; i++)
            d[i] = seg(k)->end[i] - tp.pos[i];
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
