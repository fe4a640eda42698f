/*
 * homemod.c - the homing module of the halsdk motion controller.
 *
 * motmod finds the table halsdk_homing_api (homing.h) when it loads and
 * calls it from its servo-cycle function and its command handler, all in
 * one thread: nothing here needs a lock.  Homing moves a joint only
 * through the joint's free planner (target, max_vel, enable); when a
 * home position is found it changes the joint's motor_offset and shifts
 * the joint's positions by the same amount while the planner is at rest,
 * so the motor command does not move.
 *
 * One joint's homing, in order (see docs/homing.rst):
 *   start      stop any motion, wait until the planner is at rest
 *   backoff    the switch is closed already: move off it (search speed,
 *              against the search direction) and stop
 *   search     move toward the switch at HOME_SEARCH_VEL until it closes,
 *              then stop (overshoot)
 *   clear      latch in the search direction: move off the switch again
 *   latch      at HOME_LATCH_VEL: toward the switch until it closes
 *              (same signs) or away until it opens (opposite signs)
 *   index      HOME_USE_INDEX: set index-enable and go on at latch speed
 *              until the encoder clears it
 *   settle     stop; at rest, make the latched point HOME_OFFSET
 *   sync       synchronized sequences: wait for the whole group
 *   final      move to HOME at HOME_FINAL_VEL (or the joint's max speed)
 * Sequences (HOME_SEQUENCE) are run by home_all_step() at the end of
 * each cycle.
 */

#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_math.h"
#include "rtapi_string.h"
#include "hal.h"
#include "homing.h"

MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("Homing module for the halsdk motion controller");
MODULE_LICENSE("GPL");

/* HOME_SEQUENCE value meaning "not in home all" */
#ifdef HOME_SEQUENCE_NONE
#define SEQ_NONE HOME_SEQUENCE_NONE
#else
#define SEQ_NONE (-1)
#endif

#define KNOWN_FLAGS (HOME_IGNORE_LIMITS | HOME_USE_INDEX | HOME_IS_SHARED | \
                     HOME_UNLOCK_FIRST | HOME_ABSOLUTE_ENCODER | \
                     HOME_NO_REHOME | HOME_NO_FINAL_MOVE | \
                     HOME_INDEX_NO_ENCODER_RESET)

/* the number on joint.N.home-state */
enum hstate {
    HS_IDLE = 0,
    HS_START = 1,           /* stopping before homing */
    HS_BACKOFF = 2,         /* leaving a switch closed at start */
    HS_BACKOFF_STOP = 3,
    HS_SEARCH = 4,          /* toward the switch at search speed */
    HS_SEARCH_STOP = 5,
    HS_CLEAR = 6,           /* off the switch before a same-sign latch */
    HS_CLEAR_STOP = 7,
    HS_LATCH = 8,           /* at latch speed, waiting for the edge */
    HS_INDEX = 9,           /* index-enable set, waiting for the pulse */
    HS_SETTLE = 10,         /* stopping after the latch, then set offset */
    HS_SYNC = 11,           /* waiting for a synchronized group */
    HS_FINAL = 12,          /* final move to HOME */
    HS_DONE = 13            /* homed (shown one cycle, then idle) */
};

typedef struct {
    hal_bit_t *sw_in;           /* joint.N.home-sw-in */
    hal_bit_t *homing;          /* joint.N.homing */
    hal_bit_t *homed;           /* joint.N.homed */
    hal_s32_t *state;           /* joint.N.home-state */
    hal_bit_t *index_enable;    /* joint.N.index-enable (IO) */
} home_pins_t;

typedef struct {
    mot_home_params_t p;
    int state;                  /* enum hstate */
    int homing;                 /* 1 from start until done or abort */
    int homed;
    int sw, sw_old;             /* home switch now / at the last edge test */
    int ie_armed;               /* we set index-enable, waiting for clear */
    int ie_found;               /* the encoder cleared it */
    int ie_write;               /* -1: leave the pin; 0/1: write it */
    double latch;               /* latched point, joint coords before shift */
    int latched;                /* latch is valid */
    double prev_fb, prev_cmd;   /* pos_fb, pos_cmd of the last cycle */
    double final_vel;           /* speed of the final move */
} home_joint_t;

static int comp_id = -1;        /* homemod's own component */
/* the state of the module: one home_t, handed to every function below.
   The functions of the homing.h table (hm_*) carry no context: motmod
   calls them as a custom homing module's would be called, so each of them
   takes the module's one home_t (homing) and hands it on */
typedef struct {
    int nj;                     /* joints (extra ones included) */
    double dt;                  /* servo period, s */
    mot_joint_t *J;             /* motmod's joint array */
    home_joint_t *H;            /* hal_malloc'd, nj */
    home_pins_t *P;             /* hal_malloc'd, nj */
    int all_seq;                /* home all: sequence running, -1: none */
    char errbuf[256];           /* failures not yet taken */
    char errout[256];           /* the text take_error() handed out */
} home_t;

static home_t homing = {.all_seq = -1};

/* ---- small helpers ---- */

static void why_set(char *why, int whylen, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void why_set(char *why, int whylen, const char *fmt, ...)
{
    va_list ap;
    if (!why || whylen <= 0)
        return;
    va_start(ap, fmt);
    vsnprintf(why, whylen, fmt, ap);
    va_end(ap);
}

/* remember a failure for take_error(); several in one cycle are joined */
static void post(home_t *home, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static void post(home_t *home, const char *fmt, ...)
{
    va_list ap;
    size_t n = strlen(home->errbuf);
    if (n > 0 && n + 2 < sizeof(home->errbuf)) {
        strcpy(home->errbuf + n, "; ");
        n += 2;
    }
    if (n + 1 >= sizeof(home->errbuf))
        return;
    va_start(ap, fmt);
    vsnprintf(home->errbuf + n, sizeof(home->errbuf) - n, fmt, ap);
    va_end(ap);
}

static int bad_joint(const home_t *home, int j, char *why, int whylen)
{
    if (!home->J) {
        why_set(why, whylen, "homing is not initialized (motmod not loaded)");
        return 1;
    }
    if (j < 0 || j >= home->nj) {
        why_set(why, whylen, "joint %d does not exist (num_joints=%d)", j,
                home->nj);
        return 1;
    }
    return 0;
}

static int seq_set(const home_t *home, int j)
{
    return home->H[j].p.home_sequence != SEQ_NONE;
}

static int seq_abs(const home_t *home, int j)
{
    int s = home->H[j].p.home_sequence;
    return s < 0 ? -s : s;
}

/* a group (|sequence|) is synchronized when any member is negative */
static int group_sync(const home_t *home, int g)
{
    int k;
    for (k = 0; k < home->nj; k++)
        if (seq_set(home, k) && seq_abs(home, k) == g &&
            home->H[k].p.home_sequence < 0)
            return 1;
    return 0;
}

static int abs_mode(const home_t *home, int j)
{
    if (!(home->H[j].p.flags & HOME_ABSOLUTE_ENCODER))
        return 0;
    return (home->H[j].p.flags & HOME_NO_FINAL_MOVE) ? 2 : 1;
}

static double travel(const home_t *home, int j)
{
    double t = home->J[j].max_pos_limit - home->J[j].min_pos_limit;
    return (isfinite(t) && t > 0) ? t : 0;
}

/* a speed limited by the joint's velocity limit */
static double speed(const home_t *home, int j, double v)
{
    v = fabs(v);
    if (home->J[j].vel_limit > 0 && v > home->J[j].vel_limit)
        v = home->J[j].vel_limit;
    return v;
}

static void move(home_t *home, int j, double target, double vel)
{
    freeplan_t *fp = &home->J[j].free_tp;
    fp->target = target;
    fp->max_vel = speed(home, j, vel);
    fp->enable = 1;
}

static void halt(home_t *home, int j)
{
    home->J[j].free_tp.enable = 0;
}

static int at_rest(const home_t *home, int j)
{
    return !home->J[j].free_tp.active;
}

/* the planner at rest at pos (the effect of fp_reset(), written here
   because homemod does not link the planner code) */
static void plan_reset(freeplan_t *fp, double pos)
{
    fp->pos = pos;
    fp->target = pos;
    fp->vel = 0;
    fp->acc = 0;
    fp->enable = 0;
    fp->active = 0;
}

/* make the latched point HOME_OFFSET: a new motor offset and every joint
   position shifted by the same amount, so motor_pos_cmd does not move */
static void apply_offset(home_t *home, int j, double latched)
{
    mot_joint_t *jt = &home->J[j];
    double d = home->H[j].p.home_offset - latched;

    jt->motor_offset -= d;
    jt->pos_cmd += d;
    jt->pos_fb += d;
    jt->coarse_pos += d;
    plan_reset(&jt->free_tp, jt->free_tp.pos + d);
    home->H[j].prev_fb += d;
    home->H[j].prev_cmd += d;
}

static void set_flags(home_t *home, int j)
{
    unsigned f = home->J[j].flags & ~(MOT_JOINT_HOMING | MOT_JOINT_HOMED);
    if (home->H[j].homing)
        f |= MOT_JOINT_HOMING;
    if (home->H[j].homed)
        f |= MOT_JOINT_HOMED;
    home->J[j].flags = f;
}

/* end the homing of joint j without a home: stop its planner */
static void drop(home_t *home, int j)
{
    home_joint_t *h = &home->H[j];
    if (h->homing)
        halt(home, j);
    if (h->ie_armed)
        h->ie_write = 0;
    h->ie_armed = 0;
    h->ie_found = 0;
    h->homing = 0;
    h->homed = 0;
    h->latched = 0;
    h->state = HS_IDLE;
    set_flags(home, j);
}

/* a failure of one joint ends all homing (a home all included) */
static void fail(home_t *home, int j, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void fail(home_t *home, int j, const char *fmt, ...)
{
    char msg[200];
    va_list ap;
    int k;

    va_start(ap, fmt);
    vsnprintf(msg, sizeof(msg), fmt, ap);
    va_end(ap);
    post(home, "joint %d %s", j, msg);
    for (k = 0; k < home->nj; k++)
        if (home->H[k].homing)
            drop(home, k);
    home->all_seq = -1;
}

/* ---- the per-joint state machine ---- */

static void begin(home_t *home, int j)
{
    home_joint_t *h = &home->H[j];
    h->homing = 1;
    h->homed = 0;
    h->latched = 0;
    h->ie_armed = 0;
    h->ie_found = 0;
    h->state = HS_START;
    halt(home, j);
    set_flags(home, j);
}

static void finish(home_t *home, int j)
{
    home_joint_t *h = &home->H[j];
    h->homing = 0;
    h->homed = 1;
    h->state = HS_DONE;
    set_flags(home, j);
}

static double final_speed(const home_t *home, int j)
{
    double v = home->H[j].p.home_final_vel;
    if (!(v > 0))
        v = home->J[j].vel_limit;
    return speed(home, j, v);
}

/* after the offset is set: final move, or wait for the group, or done */
static void after_latch(home_t *home, int j)
{
    home_joint_t *h = &home->H[j];
    int g = seq_abs(home, j);

    if (abs_mode(home, j) == 2 || (h->p.flags & HOME_NO_FINAL_MOVE)) {
        finish(home, j);
        return;
    }
    h->final_vel = final_speed(home, j);
    if (seq_set(home, j) && group_sync(home, g)) {
        h->state = HS_SYNC;
        return;
    }
    move(home, j, h->p.home, h->final_vel);
    h->state = HS_FINAL;
}

/* start the latch phase from rest near the switch */
static void start_latch(home_t *home, int j)
{
    home_joint_t *h = &home->H[j];
    double ld = h->p.home_latch_vel > 0 ? 1.0 : -1.0;
    move(home, j, home->J[j].free_tp.pos + ld * travel(home, j),
         h->p.home_latch_vel);
    h->sw_old = h->sw;
    h->state = HS_LATCH;
}

/* set index-enable and move (on) at latch speed in the latch direction */
static void start_index(home_t *home, int j)
{
    home_joint_t *h = &home->H[j];
    double ld = h->p.home_latch_vel > 0 ? 1.0 : -1.0;
    move(home, j, home->J[j].free_tp.pos + ld * travel(home, j),
         h->p.home_latch_vel);
    h->ie_armed = 1;
    h->ie_found = 0;
    h->ie_write = 1;
    h->state = HS_INDEX;
}

/* the encoder cleared index-enable this cycle: find the index point in
   the joint coordinates in use before the home offset is applied */
static void index_latch(home_t *home, int j)
{
    home_joint_t *h = &home->H[j];
    mot_joint_t *jt = &home->J[j];

    if (h->p.flags & HOME_INDEX_NO_ENCODER_RESET) {
        h->latch = jt->pos_fb;
    } else {
        /* the encoder count restarted at zero on the index, so
           motor_pos_fb jumped; take the jump into the motor offset now
           (estimated from the last cycle, so pos_fb and the following
           error stay continuous) and read the exact index point from
           the distance the encoder reports since the pulse */
        double expect = h->prev_fb + (jt->pos_cmd - h->prev_cmd);
        double jump = jt->pos_fb - expect;
        if (isfinite(jump)) {
            jt->motor_offset += jump;
            jt->pos_fb -= jump;
            jt->ferror = jt->pos_cmd - jt->pos_fb;
        }
        h->latch = jt->pos_fb - jt->motor_pos_fb;
    }
    h->latched = 1;
}

static void step_joint(home_t *home, int j)
{
    home_joint_t *h = &home->H[j];
    mot_joint_t *jt = &home->J[j];
    double sdir = h->p.home_search_vel > 0 ? 1.0 : -1.0;
    double pos = jt->free_tp.pos;
    double t = travel(home, j);

    switch (h->state) {
    case HS_START:
        if (!at_rest(home, j))
            break;
        if (abs_mode(home, j)) {
            apply_offset(home, j, jt->pos_fb);
            after_latch(home, j);
            break;
        }
        if (h->p.home_search_vel == 0) {
            if (h->p.flags & HOME_USE_INDEX) {
                if (t <= 0) {
                    fail(home, j, "homing: soft limits not set, no index "
                         "search distance");
                    break;
                }
                start_index(home, j);
            } else {
                /* immediate: the commanded position is the home point */
                apply_offset(home, j, jt->pos_cmd);
                after_latch(home, j);
            }
            break;
        }
        if (t <= 0) {
            fail(home, j, "homing: soft limits not set, no search distance");
            break;
        }
        if (h->sw) {
            if (h->p.flags & HOME_IS_SHARED) {
                fail(home, j, "home switch already closed at start of search "
                     "(HOME_IS_SHARED)");
                break;
            }
            move(home, j, pos - sdir * t, h->p.home_search_vel);
            h->state = HS_BACKOFF;
            break;
        }
        move(home, j, sdir > 0 ? fmax(pos, jt->max_pos_limit) + t
                         : fmin(pos, jt->min_pos_limit) - t,
             h->p.home_search_vel);
        h->state = HS_SEARCH;
        break;

    case HS_BACKOFF:
        if (!h->sw) {
            halt(home, j);
            h->state = HS_BACKOFF_STOP;
        } else if (at_rest(home, j)) {
            fail(home, j, "homing: home switch stayed closed while "
                 "backing off");
        }
        break;

    case HS_BACKOFF_STOP:
        if (!at_rest(home, j))
            break;
        move(home, j, sdir > 0 ? fmax(pos, jt->max_pos_limit) + t
                         : fmin(pos, jt->min_pos_limit) - t,
             h->p.home_search_vel);
        h->state = HS_SEARCH;
        break;

    case HS_SEARCH:
        if (h->sw) {
            halt(home, j);
            h->state = HS_SEARCH_STOP;
        } else if (at_rest(home, j)) {
            fail(home, j, "homing: search ended without finding the switch");
        }
        break;

    case HS_SEARCH_STOP:
        if (!at_rest(home, j))
            break;
        if ((h->p.home_latch_vel > 0) == (sdir > 0)) {
            /* same direction: get off the switch first */
            move(home, j, pos - sdir * t, h->p.home_search_vel);
            h->state = HS_CLEAR;
        } else {
            start_latch(home, j);
        }
        break;

    case HS_CLEAR:
        if (!h->sw) {
            halt(home, j);
            h->state = HS_CLEAR_STOP;
        } else if (at_rest(home, j)) {
            fail(home, j, "homing: home switch stayed closed while "
                 "backing off");
        }
        break;

    case HS_CLEAR_STOP:
        if (at_rest(home, j))
            start_latch(home, j);
        break;

    case HS_LATCH: {
        /* same signs: the switch closing; opposite: the switch opening */
        int rise = (h->p.home_latch_vel > 0) == (sdir > 0);
        int edge = rise ? (h->sw && !h->sw_old) : (!h->sw && h->sw_old);
        h->sw_old = h->sw;
        if (edge) {
            if (h->p.flags & HOME_USE_INDEX) {
                start_index(home, j);
            } else {
                h->latch = jt->pos_fb;
                h->latched = 1;
                halt(home, j);
                h->state = HS_SETTLE;
            }
        } else if (at_rest(home, j)) {
            fail(home, j, "homing: latch move ended without the home "
                 "switch %s", rise ? "closing" : "opening");
        }
        break;
    }

    case HS_INDEX:
        if (h->ie_found) {
            h->ie_found = 0;
            h->ie_armed = 0;
            index_latch(home, j);
            halt(home, j);
            h->state = HS_SETTLE;
        } else if (at_rest(home, j)) {
            fail(home, j, "index pulse not found");
        }
        break;

    case HS_SETTLE:
        if (!at_rest(home, j))
            break;
        apply_offset(home, j, h->latch);
        after_latch(home, j);
        break;

    case HS_SYNC:
        /* handled for the whole group by sync_step(home) */
        break;

    case HS_FINAL:
        if (at_rest(home, j))
            finish(home, j);
        break;

    default:
        break;
    }
}

/* start the final moves of a synchronized group when all its homing
   members wait; speeds are scaled so the moves take the same time */
static void sync_step(home_t *home)
{
    int k, g;
    for (g = 0; g <= home->nj; g++) {
        int n = 0, ready = 1;
        double tmax = 0;
        for (k = 0; k < home->nj; k++) {
            if (!home->H[k].homing || !seq_set(home, k) ||
                seq_abs(home, k) != g)
                continue;
            n++;
            if (home->H[k].state != HS_SYNC) {
                ready = 0;
                break;
            }
            if (home->H[k].final_vel > 0) {
                double tk = fabs(home->H[k].p.home - home->J[k].free_tp.pos)
                            / home->H[k].final_vel;
                if (tk > tmax)
                    tmax = tk;
            }
        }
        if (!n || !ready)
            continue;
        for (k = 0; k < home->nj; k++) {
            double v;
            if (!home->H[k].homing || !seq_set(home, k) ||
                seq_abs(home, k) != g)
                continue;
            v = home->H[k].final_vel;
            if (tmax > 0) {
                double vs = fabs(home->H[k].p.home -
                                 home->J[k].free_tp.pos) / tmax;
                if (vs > 0 && vs < v)
                    v = vs;
            }
            move(home, k, home->H[k].p.home, v);
            home->H[k].state = HS_FINAL;
        }
    }
}

/* ---- starting ---- */

/* checks that do not depend on the other joints */
static int can_start(home_t *home, int j, int quiet, char *why, int whylen)
{
    home_joint_t *h = &home->H[j];
    mot_joint_t *jt = &home->J[j];

    if (!(jt->flags & MOT_JOINT_ACTIVE)) {
        why_set(why, whylen, "joint %d is not active", j);
        return quiet ? 1 : -EINVAL;     /* home all skips it */
    }
    if (h->homing) {
        why_set(why, whylen, "joint %d is homing already", j);
        return -EBUSY;
    }
    if (h->homed && abs_mode(home, j)) {
        why_set(why, whylen, "joint %d has an absolute encoder and is "
                "homed already (unhome it first)", j);
        return quiet ? 1 : -EINVAL;
    }
    if (h->homed && (h->p.flags & HOME_NO_REHOME)) {
        why_set(why, whylen, "joint %d is homed and HOME_NO_REHOME is set "
                "(unhome it first)", j);
        return quiet ? 1 : -EINVAL;
    }
    if (jt->min_pos_limit < jt->max_pos_limit &&
        (h->p.home < jt->min_pos_limit || h->p.home > jt->max_pos_limit) &&
        !(abs_mode(home, j) == 2 || (h->p.flags & HOME_NO_FINAL_MOVE))) {
        why_set(why, whylen, "joint %d: HOME %g is outside the soft limits "
                "[%g, %g]", j, h->p.home, jt->min_pos_limit,
                jt->max_pos_limit);
        return -EINVAL;
    }
    if (!abs_mode(home, j) && h->p.home_search_vel != 0 &&
        (h->p.flags & HOME_IS_SHARED) && h->sw) {
        why_set(why, whylen, "joint %d home switch already closed at start "
                "of search (HOME_IS_SHARED)", j);
        return -EBUSY;
    }
    return 0;
}

static int any_homing(const home_t *home)
{
    int k;
    for (k = 0; k < home->nj; k++)
        if (home->H[k].homing)
            return 1;
    return 0;
}

/* the joints of group g (not skipped ones) start now; returns the number
   started or a negative errno */
static int start_group(home_t *home, int g, int quiet, char *why, int whylen)
{
    int k, r, n = 0;
    for (k = 0; k < home->nj; k++) {
        if (!seq_set(home, k) || seq_abs(home, k) != g)
            continue;
        r = can_start(home, k, quiet, why, whylen);
        if (r < 0)
            return r;
    }
    for (k = 0; k < home->nj; k++) {
        if (!seq_set(home, k) || seq_abs(home, k) != g)
            continue;
        if (can_start(home, k, 1, NULL, 0) == 1)
            continue;   /* home all skips inactive joints, homed abs /
                           no-rehome */
        begin(home, k);
        n++;
    }
    return n;
}

static int home_all(home_t *home, char *why, int whylen)
{
    int k, g, lo = -1, hi = -1, r;

    for (k = 0; k < home->nj; k++) {
        if (!seq_set(home, k))
            continue;
        g = seq_abs(home, k);
        if (lo < 0 || g < lo)
            lo = g;
        if (g > hi)
            hi = g;
    }
    if (lo < 0) {
        why_set(why, whylen, "no joint has a HOME_SEQUENCE: home all has "
                "nothing to do");
        return -EINVAL;
    }
    if (lo > 1) {
        why_set(why, whylen, "HOME_SEQUENCE must start at 0 or 1 "
                "(lowest is %d)", lo);
        return -EINVAL;
    }
    for (g = lo; g <= hi; g++) {
        for (k = 0; k < home->nj; k++)
            if (seq_set(home, k) && seq_abs(home, k) == g)
                break;
        if (k == home->nj) {
            why_set(why, whylen, "HOME_SEQUENCE has a gap: no joint has "
                    "sequence %d but some have %d", g, hi);
            return -EINVAL;
        }
    }
    /* check every group now, so home all does not stop half-way on a
       configuration error */
    for (k = 0; k < home->nj; k++) {
        if (!seq_set(home, k))
            continue;
        r = can_start(home, k, 1, why, whylen);
        if (r < 0)
            return r;
    }
    for (g = lo; g <= hi; g++) {
        r = start_group(home, g, 1, why, whylen);
        if (r < 0)
            return r;
        if (r > 0)
            break;
    }
    home->all_seq = g <= hi ? g : -1;
    return 0;
}

/* home all: when the running group has finished, start the next one */
static void home_all_step(home_t *home)
{
    int k, g, hi = -1;
    char why[160];

    if (home->all_seq < 0)
        return;
    for (k = 0; k < home->nj; k++) {
        if (seq_set(home, k) && seq_abs(home, k) == home->all_seq &&
            home->H[k].homing)
            return;
        if (seq_set(home, k) && seq_abs(home, k) > hi)
            hi = seq_abs(home, k);
    }
    for (g = home->all_seq + 1; g <= hi; g++) {
        int r = start_group(home, g, 1, why, sizeof(why));
        if (r < 0) {
            post(home, "home all stopped at sequence %d: %s", g, why);
            home->all_seq = -1;
            return;
        }
        if (r > 0) {
            home->all_seq = g;
            return;
        }
    }
    home->all_seq = -1;
}

/* ---- the API ---- */

static int hm_init(int mot_comp, double servo_period, int njoints,
                   int nextra, mot_joint_t *joints)
{
    home_t *home = &homing;
    int j, r;

    (void)nextra;
    if (!joints || njoints <= 0 || !(servo_period > 0)) {
        rtapi_print_msg(RTAPI_MSG_ERR, "homemod: bad init arguments\n");
        return -EINVAL;
    }
    home->H = hal_malloc(njoints * sizeof(*home->H));
    home->P = hal_malloc(njoints * sizeof(*home->P));
    if (!home->H || !home->P) {
        rtapi_print_msg(RTAPI_MSG_ERR, "homemod: out of HAL memory\n");
        return -ENOMEM;
    }
    memset(home->H, 0, njoints * sizeof(*home->H));
    for (j = 0; j < njoints; j++) {
        home_pins_t *p = &home->P[j];
        if ((r = hal_pin_bit_newf(HAL_IN, &p->sw_in, mot_comp,
                                  "joint.%d.home-sw-in", j)) < 0 ||
            (r = hal_pin_bit_newf(HAL_OUT, &p->homing, mot_comp,
                                  "joint.%d.homing", j)) < 0 ||
            (r = hal_pin_bit_newf(HAL_OUT, &p->homed, mot_comp,
                                  "joint.%d.homed", j)) < 0 ||
            (r = hal_pin_s32_newf(HAL_OUT, &p->state, mot_comp,
                                  "joint.%d.home-state", j)) < 0 ||
            (r = hal_pin_bit_newf(HAL_IO, &p->index_enable, mot_comp,
                                  "joint.%d.index-enable", j)) < 0) {
            rtapi_print_msg(RTAPI_MSG_ERR, "homemod: joint %d: pins not "
                            "created (%d)\n", j, r);
            return r;
        }
        *p->sw_in = 0;
        *p->homing = 0;
        *p->homed = 0;
        *p->state = 0;
        *p->index_enable = 0;
        home->H[j].p.home_sequence = SEQ_NONE;
        home->H[j].ie_write = -1;
    }
    home->nj = njoints;
    home->dt = servo_period;
    home->J = joints;
    home->all_seq = -1;
    home->errbuf[0] = 0;
    return 0;
}

static void hm_read_inputs(void)
{
    home_t *home = &homing;
    int j;
    if (!home->J)
        return;
    for (j = 0; j < home->nj; j++) {
        home_joint_t *h = &home->H[j];
        h->sw = *home->P[j].sw_in ? 1 : 0;
        if (h->ie_armed && h->ie_write < 0 && !*home->P[j].index_enable)
            h->ie_found = 1;
    }
}

static void hm_write_outputs(void)
{
    home_t *home = &homing;
    int j;
    if (!home->J)
        return;
    for (j = 0; j < home->nj; j++) {
        home_joint_t *h = &home->H[j];
        home_pins_t *p = &home->P[j];
        if (h->ie_write >= 0) {
            *p->index_enable = h->ie_write;
            h->ie_write = -1;
        }
        *p->homing = h->homing;
        *p->homed = h->homed;
        *p->state = h->state;
    }
}

static int hm_set_params(int j, const mot_home_params_t *in, char *why,
                         int whylen)
{
    home_t *home = &homing;
    mot_home_params_t p;
    mot_joint_t *jt;

    if (bad_joint(home, j, why, whylen))
        return -EINVAL;
    if (!in) {
        why_set(why, whylen, "joint %d: no homing parameters", j);
        return -EINVAL;
    }
    p = *in;
    jt = &home->J[j];
    if (home->H[j].homing) {
        why_set(why, whylen, "joint %d is homing: parameters cannot change "
                "now", j);
        return -EBUSY;
    }
#define FINITE(f, key)                                                    \
    if (!isfinite(p.f)) {                                                 \
        why_set(why, whylen, "joint %d: " key " is not a finite number", j); \
        return -EINVAL;                                                   \
    }
    FINITE(home_offset, "HOME_OFFSET");
    FINITE(home, "HOME");
    FINITE(home_search_vel, "HOME_SEARCH_VEL");
    FINITE(home_latch_vel, "HOME_LATCH_VEL");
    FINITE(home_final_vel, "HOME_FINAL_VEL");
#undef FINITE
    if (p.flags & ~KNOWN_FLAGS) {
        why_set(why, whylen, "joint %d: unknown homing flags 0x%x", j,
                p.flags & ~KNOWN_FLAGS);
        return -EINVAL;
    }
    if (!(p.flags & HOME_ABSOLUTE_ENCODER)) {
        if (p.home_search_vel != 0 && p.home_latch_vel == 0) {
            why_set(why, whylen, "joint %d: HOME_LATCH_VEL is 0 but "
                    "HOME_SEARCH_VEL is not (the latch needs a speed)", j);
            return -EINVAL;
        }
        if ((p.flags & HOME_USE_INDEX) && p.home_latch_vel == 0) {
            why_set(why, whylen, "joint %d: HOME_USE_INDEX needs a nonzero "
                    "HOME_LATCH_VEL (the index search speed)", j);
            return -EINVAL;
        }
    }
    if (p.home_sequence != SEQ_NONE &&
        (p.home_sequence > home->nj || p.home_sequence < -home->nj)) {
        why_set(why, whylen, "joint %d: HOME_SEQUENCE %d is out of range "
                "(sequences run 0..%d without gaps)", j, p.home_sequence,
                home->nj);
        return -EINVAL;
    }
    if (jt->min_pos_limit < jt->max_pos_limit &&
        (p.home < jt->min_pos_limit || p.home > jt->max_pos_limit) &&
        !(p.flags & HOME_NO_FINAL_MOVE)) {
        why_set(why, whylen, "joint %d: HOME %g is outside the soft limits "
                "[%g, %g]", j, p.home, jt->min_pos_limit, jt->max_pos_limit);
        return -EINVAL;
    }
    p.volatile_home = p.volatile_home ? 1 : 0;
    home->H[j].p = p;
    return 0;
}

static int hm_start(int j, char *why, int whylen)
{
    home_t *home = &homing;
    int r, g, k;

    if (!home->J) {
        why_set(why, whylen, "homing is not initialized (motmod not loaded)");
        return -EINVAL;
    }
    if (any_homing(home) || home->all_seq >= 0) {
        why_set(why, whylen, "homing is in progress already");
        return -EBUSY;
    }
    if (j == -1)
        return home_all(home, why, whylen);
    if (bad_joint(home, j, why, whylen))
        return -EINVAL;
    r = can_start(home, j, 0, why, whylen);
    if (r < 0)
        return r;
    if (seq_set(home, j)) {
        g = seq_abs(home, j);
        /* the order of the sequences holds for single joints too */
        for (k = 0; k < home->nj; k++) {
            if (seq_set(home, k) && seq_abs(home, k) < g && !home->H[k].homed
                && (home->J[k].flags & MOT_JOINT_ACTIVE)) {
                why_set(why, whylen, "joint %d (HOME_SEQUENCE %d) cannot "
                        "home before joint %d (HOME_SEQUENCE %d) is homed",
                        j, home->H[j].p.home_sequence, k,
                        home->H[k].p.home_sequence);
                return -EINVAL;
            }
        }
        if (group_sync(home, g)) {
            /* a synchronized group homes together */
            for (k = 0; k < home->nj; k++) {
                if (k == j || !seq_set(home, k) || seq_abs(home, k) != g)
                    continue;
                r = can_start(home, k, 0, why, whylen);
                if (r < 0)
                    return r;
            }
            start_group(home, g, 0, why, whylen);
            return 0;
        }
    }
    begin(home, j);
    return 0;
}

static int hm_unhome(int j, char *why, int whylen)
{
    home_t *home = &homing;
    int k;

    if (!home->J) {
        why_set(why, whylen, "homing is not initialized (motmod not loaded)");
        return -EINVAL;
    }
    if (j == -1 || j == -2) {
        for (k = 0; k < home->nj; k++) {
            if (j == -2 && !home->H[k].p.volatile_home)
                continue;
            if (home->H[k].homing) {
                why_set(why, whylen, "joint %d is homing: abort it before "
                        "unhoming", k);
                return -EBUSY;
            }
        }
        for (k = 0; k < home->nj; k++) {
            if (j == -2 && !home->H[k].p.volatile_home)
                continue;
            home->H[k].homed = 0;
            if (home->H[k].state == HS_DONE)
                home->H[k].state = HS_IDLE;
            set_flags(home, k);
        }
        return 0;
    }
    if (bad_joint(home, j, why, whylen))
        return -EINVAL;
    if (home->H[j].homing) {
        why_set(why, whylen, "joint %d is homing: abort it before unhoming",
                j);
        return -EBUSY;
    }
    home->H[j].homed = 0;
    if (home->H[j].state == HS_DONE)
        home->H[j].state = HS_IDLE;
    set_flags(home, j);
    return 0;
}

static void hm_abort(void)
{
    home_t *home = &homing;
    int k, n = 0;
    char list[96];
    size_t len = 0;

    if (!home->J)
        return;
    list[0] = 0;
    for (k = 0; k < home->nj; k++) {
        if (!home->H[k].homing)
            continue;
        if (len + 8 < sizeof(list))
            len += snprintf(list + len, sizeof(list) - len, "%s%d",
                            n ? ", " : "", k);
        n++;
        drop(home, k);
    }
    home->all_seq = -1;
    if (n)
        post(home, "homing aborted (joint%s %s)", n > 1 ? "s" : "", list);
}

static int hm_run(void)
{
    home_t *home = &homing;
    int j, busy = 0;

    if (!home->J)
        return 0;
    for (j = 0; j < home->nj; j++) {
        home_joint_t *h = &home->H[j];
        if (h->state == HS_DONE && !h->homing)
            h->state = HS_IDLE;
        if (h->homing) {
            step_joint(home, j);
            busy = 1;
        }
    }
    if (!busy && home->all_seq < 0)
        return 0;
    sync_step(home);
    home_all_step(home);
    busy = 0;
    for (j = 0; j < home->nj; j++) {
        if (!home->H[j].homing)
            continue;
        /* for the estimate of an encoder reset (index_latch) */
        home->H[j].prev_fb = home->J[j].pos_fb;
        home->H[j].prev_cmd = home->J[j].pos_cmd;
        busy = 1;
    }
    return busy || home->all_seq >= 0;
}

static int hm_is_homed(int j)
{
    home_t *home = &homing;
    return home->J && j >= 0 && j < home->nj && home->H[j].homed;
}

static int hm_is_homing(int j)
{
    home_t *home = &homing;
    return home->J && j >= 0 && j < home->nj && home->H[j].homing;
}

/* all active joints homed (and at least one active) */
static int hm_all_homed(void)
{
    home_t *home = &homing;
    int j, n = 0;
    if (!home->J)
        return 0;
    for (j = 0; j < home->nj; j++) {
        if (!(home->J[j].flags & MOT_JOINT_ACTIVE))
            continue;
        if (!home->H[j].homed)
            return 0;
        n++;
    }
    return n > 0;
}

static int hm_state(int j)
{
    home_t *home = &homing;
    return (home->J && j >= 0 && j < home->nj) ? home->H[j].state : 0;
}

static int hm_ignores_limits(int j)
{
    home_t *home = &homing;
    return home->J && j >= 0 && j < home->nj && home->H[j].homing &&
           (home->H[j].p.flags & HOME_IGNORE_LIMITS);
}

static const char *hm_take_error(void)
{
    home_t *home = &homing;
    if (!home->errbuf[0])
        return "";
    strncpy(home->errout, home->errbuf, sizeof(home->errout) - 1);
    home->errout[sizeof(home->errout) - 1] = 0;
    home->errbuf[0] = 0;
    return home->errout;
}

const mot_homing_api_t halsdk_homing_api = {
    .version = HALSDK_HOMING_VERSION,
    .init = hm_init,
    .read_inputs = hm_read_inputs,
    .write_outputs = hm_write_outputs,
    .set_params = hm_set_params,
    .start = hm_start,
    .unhome = hm_unhome,
    .abort = hm_abort,
    .run = hm_run,
    .is_homed = hm_is_homed,
    .is_homing = hm_is_homing,
    .all_homed = hm_all_homed,
    .state = hm_state,
    .ignores_limits = hm_ignores_limits,
    .take_error = hm_take_error,
};
EXPORT_SYMBOL(halsdk_homing_api);

int rtapi_app_main(void)
{
    comp_id = hal_init("homemod");
    if (comp_id < 0)
        return comp_id;
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    homing.J = NULL;
    if (comp_id >= 0)
        hal_exit(comp_id);
}
