/*
 * tp_priv.h - private to tpmod, the trajectory planner: the types its
 * sources share, small helpers, and the functions one source uses from
 * another:
 *
 *   tpmod.c         module entry, parameters, the tp.h interface
 *                   (halsdk_tp_api) and the planner state it owns
 *   tp_geom.c       segments: line and circle paths, tangents, limits
 *   tp_lookahead.c  junction caps, planning acceleration, the backward
 *                   velocity pass, stopping / junction velocities
 *   tp_blend.c      corner blend arcs (G64 P), line merging (G64 Q)
 *   tp_queue.c      checking and queueing moves, popping, flushing
 *   tp_cycle.c      one cycle: velocity, walk, advance, synchronized
 *                   moves, rigid taps, probing, synchronized outputs
 *
 * The whole planner state is one tp_t; tpmod.c holds the only one, and
 * every function that reads or changes it takes it as its first
 * argument (const when it only reads it).  The functions run in the
 * servo thread: no allocation, no locks.
 */
#ifndef HALSDK_TP_PRIV_H
#define HALSDK_TP_PRIV_H

#include "rtapi.h"
#include "rtapi_math.h"
#include "rtapi_string.h"
#include "hal.h"
#include "tp.h"

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

/* the junctions of one look-ahead walk (tp_cycle.c) */
typedef struct {
    double dist;                /* from here to the end of the segment */
    double vf;                  /* velocity limit at the junction */
    double ws;                  /* the next segment's requested velocity */
    int stop;
    int composed;               /* vf comes from later junctions */
} tp_walk_t;

typedef struct tp_t {
    int comp_id;                /* motmod's, from init() */
    int inited;
    int queue_size;             /* moves the queue holds (module parameter) */
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

    tp_walk_t wk[MAX_WALK];     /* the junctions of this cycle's walk */

    char err[128];
} tp_t;

/* ---------------------------------------------------------------- helpers */

static inline void pose_to(const EmcPose *p, double *v)
{
    int i;
    for (i = 0; i < NAX; i++)
        v[i] = *emcpose_axis((EmcPose *)p, i);
}

static inline void to_pose(const double *v, EmcPose *p)
{
    int i;
    for (i = 0; i < NAX; i++)
        *emcpose_axis(p, i) = v[i];
}

static inline double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline double norm3(const double *a)
{
    return sqrt(dot3(a, a));
}

static inline void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double dmin(double a, double b)
{
    return a < b ? a : b;
}

static inline double dmax(double a, double b)
{
    return a > b ? a : b;
}

static inline int finite_pose(const EmcPose *p)
{
    double v[NAX];
    int i;
    pose_to(p, v);
    for (i = 0; i < NAX; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

static inline void set_error(tp_t *tp, const char *msg)
{
    rtapi_snprintf(tp->err, sizeof(tp->err), "%s", msg);
}

/* the k-th queued segment */
static inline int slot(const tp_t *tp, int k)
{
    return (tp->head + k) % tp->nslots;
}

static inline tc_t *seg(const tp_t *tp, int k)
{
    return &tp->q[slot(tp, k)];
}

static inline tc_t *tail(const tp_t *tp)
{
    return tp->count ? seg(tp, tp->count - 1) : NULL;
}

/* ---- tpmod.c */
int why_(char *why, int len, int ret, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* ---- tp_geom.c */
void line_setup(const tp_t *tp, tc_t *tc);
void line_eval(const tc_t *tc, double s, double *p);
void circle_limits(const tp_t *tp, tc_t *tc, double share);
double a_up(const tc_t *t, double v);
int circle_setup(const tp_t *tp, tc_t *tc, const PmCartesian *center,
                 const PmCartesian *normal, int turn,
                 char *why, int whylen);
void tc_eval(const tc_t *tc, double s, double *p);
void tc_tangent(const tc_t *tc, int at_end, double *t);

/* ---- tp_lookahead.c */
double stop_vel(double d, double acc, double dt);
double junction_vel(double d, double vf, double acc, double dt);
double exact_cap(const tp_t *tp, tc_t *a, tc_t *b);
void link_nb(tc_t *a, tc_t *b);
void junction_setup(const tp_t *tp, tc_t *a, tc_t *b);
void set_aplan(const tp_t *tp, tc_t *t);
double plan_vmax(const tp_t *tp, const tc_t *t);
double reach_vel(const tp_t *tp, const tc_t *b, double v);
void backward_pass(tp_t *tp, int force);

/* ---- tp_blend.c */
int can_change(const tp_t *tp, int k, double new_len);
int insert_blend(tp_t *tp, tc_t *a, tc_t *b);
int try_merge(const tp_t *tp, tc_t *t, const double *end,
              const tp_move_t *m);

/* ---- tp_queue.c */
int queue_line(tp_t *tp, const EmcPose *end, const tp_move_t *m,
               int probe_type, int rigid, char *why, int whylen);
int queue_circle(tp_t *tp, const EmcPose *end, const PmCartesian *center,
                 const PmCartesian *normal, int turn,
                 const tp_move_t *m, char *why, int whylen);
void flush_queue(tp_t *tp);
void pop_tc(tp_t *tp);

/* ---- tp_cycle.c */
void run_cycle(tp_t *tp, const tp_inputs_t *in, EmcPose *out);

#endif
