/*
 * freeplan.c - the single-coordinate planner (freeplan.h): the common
 * part and the trapezoidal profile.  The jerk-limited profile is in
 * freeplan_jerk.cpp (ruckig), reached through the fp_jerk_*() functions.
 *
 * The trapezoid works on the sampled motion itself: over each cycle the
 * velocity is constant (the value at the end of the cycle) and
 * pos += vel * dt, so the finite differences of the position trace are
 * exactly the planner's vel and acc.  Each cycle plans the rest of the
 * move anew from the present state (the fewest cycles to reach the
 * target, see plan_dist()) and takes its first velocity, so the last step
 * lands on the target exactly, new targets and limits take effect at
 * once, and a planner at rest on its target stays there without chatter.
 */

#include <errno.h>
#include <float.h>
#include <math.h>
#include <string.h>

#include "freeplan.h"

/* freeplan_jerk.cpp */
void *fp_jerk_new(void);
void fp_jerk_delete(void *impl);
void fp_jerk_reset(void *impl);
int fp_jerk_update(freeplan_t *fp, double dt, int velocity_mode,
                   double vel_goal);

/* relative slack on the bounds when deciding to land on the target in
   this cycle: far below the 1e-9 any user can see, far above rounding */
#define FP_TOL 1e-12

int fp_init(freeplan_t *fp)
{
    memset(fp, 0, sizeof(*fp));
    fp->impl = fp_jerk_new();
    return fp->impl ? 0 : -ENOMEM;
}

void fp_free(freeplan_t *fp)
{
    if (fp->impl) {
        fp_jerk_delete(fp->impl);
        fp->impl = 0;
    }
}

void fp_reset(freeplan_t *fp, double pos)
{
    fp->pos = pos;
    fp->target = pos;
    fp->vel = 0.0;
    fp->acc = 0.0;
    fp->enable = 0;
    fp->active = 0;
    if (fp->impl)
        fp_jerk_reset(fp->impl);
}

/* distance covered from the start of a cycle whose velocity is u >= 0
   when every later cycle lowers the velocity by h until it is zero:
   dt * sum over i >= 0 of max(u - i*h, 0) */
static double trap_reach(double u, double h, double dt)
{
    double n = floor(u / h);

    return dt * ((n + 1.0) * u - h * n * (n + 1.0) * 0.5);
}

/* sum of c0 + c1*i over the integers i = lo..hi */
static double lsum(double lo, double hi, double c0, double c1)
{
    double cnt = hi - lo + 1.0;

    if (cnt <= 0.0)
        return 0.0;
    return cnt * c0 + c1 * (lo + hi) * cnt * 0.5;
}

/*
 * The plans of the trapezoid.  Seen in the direction of the target (the
 * distance to go dm >= 0, the present velocity w toward the target), a
 * plan of n more cycles with a velocity cap p (0 <= p <= vmax) uses the
 * velocities
 *     v(i) = max(w - i*h, min(w + i*h, p, (n + 1 - i)*h)),  i = 1..n
 * (as fast as the cap allows, braking at h per cycle where it must, and
 * slow enough that v(n) <= h: the cycle after it stands still).  It is
 * feasible when w <= (n + 1)*h.  With p = vmax it covers the largest
 * distance that n cycles can; the planner takes the smallest n that
 * reaches dm and then the cap that covers dm exactly, so the arrival is
 * time optimal for the sampled motion and the last cycles brake by
 * whole steps of h onto the target.  plan_dist() returns the distance
 * of a plan and, in *slope, its derivative in p.
 */
static double plan_dist(double n, double p, double w, double h, double dt,
                        double *slope)
{
    double i2, lo_c, hi_r, sum, cnt;

    i2 = ceil(n + 1.0 - p / h);     /* (n + 1 - i)*h <= p from i2 on */
    if (i2 < 1.0)
        i2 = 1.0;
    if (w <= p) {
        double i1 = floor((p - w) / h);                 /* w + i*h <= p */
        double i3 = floor((n + 1.0 - w / h) * 0.5);     /* ... <= (n+1-i)h */

        hi_r = fmin(fmin(i1, i3), n);
        if (hi_r < 0.0)
            hi_r = 0.0;
        lo_c = fmax(i2, hi_r + 1.0);
        if (lo_c < i3 + 1.0)
            lo_c = i3 + 1.0;
        if (lo_c > n + 1.0)
            lo_c = n + 1.0;
        sum = lsum(1.0, hi_r, w, h);
    } else {
        double j1 = floor((w - p) / h);                 /* w - i*h >= p */

        hi_r = fmin(fmin(j1, i2 - 1.0), n);
        if (hi_r < 0.0)
            hi_r = 0.0;
        lo_c = fmax(i2, hi_r + 1.0);
        if (lo_c > n + 1.0)
            lo_c = n + 1.0;
        sum = lsum(1.0, hi_r, w, -h);
    }
    sum += lsum(lo_c, n, (n + 1.0) * h, -h);
    cnt = lo_c - 1.0 - hi_r;        /* cycles at the cap */
    if (cnt < 0.0)
        cnt = 0.0;
    sum += cnt * p;
    *slope = cnt * dt;
    return sum * dt;
}

/* the continuous-time duration of the move (a first guess of n) */
static double trap_time(double dm, double w, double vmax, double amax)
{
    double t = 0.0, vp;

    if (w > vmax) {
        t = (w - vmax) / amax;
        dm -= (w * w - vmax * vmax) / (2.0 * amax);
        w = vmax;
        if (dm < 0.0)
            dm = 0.0;
    }
    vp = sqrt((2.0 * amax * dm + w * fabs(w)) * 0.5);
    if (vp <= vmax)
        return t + (2.0 * vp - w) / amax;
    return t + (2.0 * vmax - w) / amax
        + (dm - (2.0 * vmax * vmax - w * fabs(w)) / (2.0 * amax)) / vmax;
}

/* the fewest cycles n >= nmin whose fastest plan reaches dm (less the
   rounding slack of the positions) */
static double plan_cycles(double dm, double w, double vmax, double h,
                          double dt, double nmin, double slack)
{
    double n, lo, hi, mid, sl;
    int k;

    dm -= slack;
    n = ceil(trap_time(dm, w, vmax, h / dt) / dt);
    if (!(n >= nmin))
        n = nmin;
    /* the guess is within a cycle or two: step from it */
    for (k = 0; k < 4; k++) {
        if (plan_dist(n, vmax, w, h, dt, &sl) < dm)
            n += 1.0;
        else if (n > nmin && plan_dist(n - 1.0, vmax, w, h, dt, &sl) >= dm)
            n -= 1.0;
        else
            return n;
    }
    /* otherwise search: a bracket [lo, hi] with dist(lo) < dm <= dist(hi) */
    lo = nmin - 1.0;
    hi = nmin;
    while (plan_dist(hi, vmax, w, h, dt, &sl) < dm && hi < 1e15) {
        lo = hi;
        hi = hi * 2.0 + 1.0;
    }
    while (hi - lo > 1.0) {
        mid = floor((lo + hi) * 0.5);
        if (plan_dist(mid, vmax, w, h, dt, &sl) < dm)
            lo = mid;
        else
            hi = mid;
    }
    return hi;
}

/* the cap p in [lo, hi] of the n-cycle plan that covers dm exactly;
   dist(lo) <= dm <= dist(hi).  The distance is piecewise linear in p:
   Newton steps on the present piece, kept inside the bracket. */
static double plan_cap(double dm, double n, double w, double h, double dt,
                       double lo, double hi)
{
    double p = hi, d, sl;
    int k;

    for (k = 0; k < 60; k++) {
        d = plan_dist(n, p, w, h, dt, &sl);
        if (fabs(d - dm) <= 1e-14 * (dm + h * dt))
            return p;
        if (d < dm)
            lo = p;
        else
            hi = p;
        if (sl > 0.0)
            p += (dm - d) / sl;
        if (!(sl > 0.0) || !(p > lo && p < hi))
            p = 0.5 * (lo + hi);
        if (hi - lo <= 1e-15 * hi)
            return p;
    }
    return p;
}

/* one cycle of a stop: lower |vel| by max_acc*dt toward zero */
static void trap_stop(freeplan_t *fp, double dt, double h)
{
    double v = fp->vel, v1;

    if (v > 0.0)
        v1 = (v > h) ? v - h : 0.0;
    else
        v1 = (v < -h) ? v + h : 0.0;
    fp->pos += v1 * dt;
    fp->acc = (v1 - v) / dt;
    fp->vel = v1;
    fp->active = (v1 != 0.0);
}

static void trap_update(freeplan_t *fp, double dt, double vmax, double h)
{
    double d = fp->target - fp->pos;
    double s = (d >= 0.0) ? 1.0 : -1.0;
    double dm = s * d;              /* distance to go, >= 0 */
    double w = s * fp->vel;         /* velocity toward the target */
    double v = fp->vel, ua, w1, n, nmin, lo, hi, sl, slack, tol, m;

    /* what the rounding of the positions blurs */
    slack = 4.0 * DBL_EPSILON * (fabs(fp->pos) + fabs(fp->target));

    /* land on the target in this cycle when the bounds allow it and a
       stop in the next cycle stays possible (velocity <= h) */
    ua = dm / dt;
    lo = w - h;
    hi = fmin(fmin(w + h, h), vmax);
    tol = FP_TOL * h + slack / dt;
    if (lo <= hi + FP_TOL * h && ua >= lo - tol && ua <= hi + tol) {
        /* rounding may put ua a little outside the bounds: keep the
           velocity (and so the acceleration) inside them */
        if (ua < lo - FP_TOL * h)
            ua = lo;
        if (ua > hi + FP_TOL * h)
            ua = hi;
        fp->pos = fp->target;
        fp->vel = s * ua;
        fp->acc = (fp->vel - v) / dt;
        fp->active = (fp->vel != 0.0);
        return;
    }
    if (w - h >= vmax || (w - h > 0.0 && trap_reach(w - h, h, dt) > dm)) {
        /* above the velocity limit, or the target cannot be reached
           without passing it: brake fully (and come back) */
        w1 = w - h;
    } else if (w + h <= 0.0) {
        /* moving away (or at rest far behind): accelerate toward it */
        w1 = w + h;
    } else if (vmax <= 0.0) {
        /* no motion allowed: brake to a stop and wait */
        w1 = (w > h) ? w - h : 0.0;
    } else {
        nmin = ceil(w / h - 1.0);
        if (nmin < 1.0)
            nmin = 1.0;
        n = plan_cycles(dm, w, vmax, h, dt, nmin, slack);
        lo = fmax(w - h, 0.0);
        hi = fmin(w + h, vmax);
        if (plan_dist(n, hi, w, h, dt, &sl) <= dm + slack)
            w1 = hi;                /* the cap is above this cycle */
        else if (plan_dist(n, lo, w, h, dt, &sl) >= dm - slack)
            w1 = lo;                /* the cap is below this cycle */
        else
            w1 = plan_cap(dm, n, w, h, dt, lo, hi);
        /* the plan's first velocity */
        if (w1 > n * h)
            w1 = n * h;
        if (w1 < w - h)
            w1 = w - h;
    }
    /* on the final ramp (velocities m*h, (m-1)*h, ... h) with the rest
       of the ramp still to go: put the position where the ramp says it
       is, so that the rounding of many cycles does not pile up where no
       later cycle can absorb it (the ramp is rigid) */
    m = floor(w1 / h + 0.5);
    if (m >= 1.0 && fabs(w1 - m * h) <= 1e-10 * h) {
        double rest = h * dt * m * (m - 1.0) * 0.5;

        if (fabs(dm - w1 * dt - rest) <= 1e-9 * h * dt + 4.0 * slack) {
            fp->vel = s * m * h;
            fp->pos = fp->target - s * rest;
            fp->acc = (fp->vel - v) / dt;
            fp->active = 1;
            return;
        }
    }
    fp->vel = s * w1;
    fp->pos += fp->vel * dt;
    fp->acc = (fp->vel - v) / dt;
    fp->active = 1;
}

/* advance (v, a) by t seconds at jerk j; return the distance covered */
static double jerk_seg(double *v, double *a, double j, double t)
{
    double d = *v * t + *a * t * t * 0.5 + j * t * t * t / 6.0;

    *v += *a * t + j * t * t * 0.5;
    *a += j * t;
    return d;
}

/* the time-optimal stop to zero velocity and acceleration under the
   acceleration limit A and jerk limit J (what ruckig's velocity
   interface computes): ramp the acceleration to a braking peak, hold it
   at -A if needed, ramp it back to zero as the velocity reaches zero */
static double jerk_stop_distance(double v, double a, double A, double J)
{
    double s = 1.0, dist = 0.0, ap, vz, t;

    /* the velocity where the motion settles if the acceleration goes to
       zero at once; brake against it */
    vz = v + a * fabs(a) / (2.0 * J);
    if (vz < 0.0) {
        s = -1.0;
        v = -v;
        a = -a;
    }
    ap = -sqrt(J * v + a * a * 0.5);
    if (!(ap < -A)) {
        dist += jerk_seg(&v, &a, -J, (a - ap) / J);
        dist += jerk_seg(&v, &a, J, -ap / J);
    } else {
        if (a > -A)
            dist += jerk_seg(&v, &a, -J, (a + A) / J);
        else
            dist += jerk_seg(&v, &a, J, (-A - a) / J);
        a = -A;
        t = (v - A * A / (2.0 * J)) / A;
        if (t > 0.0)
            dist += jerk_seg(&v, &a, 0.0, t);
        dist += jerk_seg(&v, &a, J, A / J);
    }
    return s * dist;
}

void fp_update(freeplan_t *fp, double dt)
{
    double vmax = fp->max_vel, amax = fp->max_acc, h;
    int stop;

    if (!(dt > 0.0) || !isfinite(dt))
        return;
    if (!isfinite(fp->pos)) {
        /* nothing sensible to plan from: stand still */
        fp->vel = fp->acc = 0.0;
        fp->active = 0;
        return;
    }
    if (!isfinite(fp->vel))
        fp->vel = 0.0;
    if (!isfinite(fp->acc))
        fp->acc = 0.0;
    if (!(amax > 0.0) || !isfinite(amax)) {
        /* no usable acceleration limit: stop at once rather than never */
        fp->vel = fp->acc = 0.0;
        fp->active = 0;
        return;
    }
    if (!(vmax >= 0.0))             /* negative or NaN: no motion */
        vmax = 0.0;
    h = amax * dt;                  /* velocity change per cycle */
    if (!(h > 0.0)) {               /* underflow: as good as no limit */
        fp->vel = fp->acc = 0.0;
        fp->active = 0;
        return;
    }
    stop = !fp->enable || !isfinite(fp->target);

    if (fp->profile == FP_JERK && fp->impl && fp->max_jerk > 0.0
        && isfinite(fp->max_jerk)) {
        double jmax = fp->max_jerk, vgoal = 0.0;
        int vmode = stop || vmax <= 0.0;

        if (fp->vel == 0.0 && fp->acc == 0.0
            && (vmode || fp->pos == fp->target)) {
            fp->active = !stop && fp->pos != fp->target;
            return;
        }
        if (!vmode) {
            /* over the velocity limit (it was lowered) or bound to pass
               it, with room to spare before the target: ruckig's
               velocity interface brings the velocity down onto the limit
               smoothly, where its position interface would brake below
               the limit and accelerate again */
            double s = (fp->target >= fp->pos) ? 1.0 : -1.0;
            double w = s * fp->vel, aw = s * fp->acc;
            double peak = w + (aw > 0.0 ? aw * aw / (2.0 * jmax) : 0.0);
            double room = s * (fp->target - fp->pos)
                - s * jerk_stop_distance(fp->vel, fp->acc, amax, jmax)
                - 2.0 * fabs(fp->vel) * dt;

            if (peak > vmax * (1.0 + FP_TOL) && room > 0.0) {
                vmode = 1;
                vgoal = s * vmax;
            }
        }
        if (fp_jerk_update(fp, dt, vmode, vgoal) == 0) {
            if (!stop && vmode)
                fp->active = 1;
            return;
        }
        /* ruckig failed even for a stop: brake without the jerk limit */
        trap_stop(fp, dt, h);
        return;
    }

    if (stop)
        trap_stop(fp, dt, h);
    else
        trap_update(fp, dt, vmax, h);
}

double fp_stopping_distance(const freeplan_t *fp)
{
    double v = fp->vel, a = fp->acc, amax = fp->max_acc;

    if (!isfinite(v) || !(amax > 0.0) || !isfinite(amax))
        return 0.0;
    if (!isfinite(a))
        a = 0.0;
    if (fp->profile == FP_JERK && fp->impl && fp->max_jerk > 0.0
        && isfinite(fp->max_jerk))
        return jerk_stop_distance(v, a, amax, fp->max_jerk);
    /* trapezoid: the continuous-time distance v^2/2a; the sampled stop
       is shorter by |v|*dt/2 at most */
    return v * fabs(v) / (2.0 * amax);
}
