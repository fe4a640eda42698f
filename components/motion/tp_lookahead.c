/*
 * tp_lookahead.c - the junctions and the look-ahead of the trajectory
 * planner (tpmod): the junction cap between two segments (the exact-path
 * rule, top of tpmod.c), the acceleration the planner plans a segment
 * with, the backward velocity pass over the queue that gives every
 * segment its end velocity vend, and the discrete stopping and junction
 * velocities that the cycle (tp_cycle.c) plans each step with.
 */

#include "tp_priv.h"

/* the highest velocity v for this cycle after which the rest d of the
   path can still be covered stopping in whole cycles with decelerations
   of at most acc (v, v - acc*dt, v - 2*acc*dt, ... sum to d / dt) */
double stop_vel(double d, double acc, double dt)
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
double junction_vel(double d, double vf, double acc, double dt)
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
   else the exact-path rule (top of tpmod.c); corner flags set */
double exact_cap(const tp_t *tp, tc_t *a, tc_t *b)
{
    double ta[NAX], tb[NAX], cap = BIG, dn = 0;
    int i;

    tc_tangent(a, 1, ta);
    tc_tangent(b, 0, tb);
    for (i = 0; i < NAX; i++) {
        double du = fabs(tb[i] - ta[i]);
        dn += du * du;
        if (du > 1e-12 && tp->ax_acc[i] > 0)
            cap = dmin(cap, 0.5 * tp->ax_acc[i] * tp->dt / du);
    }
    dn = sqrt(dn);
    if (dn > 1e-12)
        cap = dmin(cap, 0.5 * dmin(a->m.acc, b->m.acc) * tp->dt / dn);
    return cap;
}

static int is_stop_type(const tc_t *t)
{
    return t->probe_type >= 0 || t->rigid || t->m.sync != TP_SYNC_NONE;
}

/* set a's cap and the corner flags of the junction a -> b */
void link_nb(tc_t *a, tc_t *b)
{
    a->anb = dmin(a->anb, b->amax);
    b->anb = dmin(b->anb, a->amax);
}

void junction_setup(const tp_t *tp, tc_t *a, tc_t *b)
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
    a->cap = exact_cap(tp, a, b);
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
    if (corner && a->cap < 2 * dmin(a->amax, b->amax) * tp->dt) {
        a->cap = 0;
        a->corner_out = b->corner_in = 0;
    }
}

/* the acceleration the look-ahead plans with: the full one, but half on
   short segments next to a corner, where every cycle may pass one (see
   run_planned, tp_cycle.c) */
void set_aplan(const tp_t *tp, tc_t *t)
{
    double vm = dmin(t->vmax, t->m.ini_maxvel);
    int near = t->len < 4 * vm * tp->dt + 1e-9;
    t->aplan = ((t->corner_in || t->corner_out) && near)
        ? 0.5 * t->amax : t->amax;
}

double plan_vmax(const tp_t *tp, const tc_t *t)
{
    double v = t->vmax;
    if (tp->vel_limit > 0 && tp->vel_limit < v)
        v = tp->vel_limit;
    return v;
}

/* the highest velocity at the start of segment b from which its end can
   be reached at v (continuous, with a margin on the acceleration; less one
   step on a long segment: the cycle after passing a junction may be held
   to the lower acceleration of the segments it touched) */
double reach_vel(const tp_t *tp, const tc_t *b, double v)
{
    double a = b->aplan, r;
    /* a short segment next to a corner is passed in cycles that also
       touch its neighbours: plan it with their acceleration too */
    if (a < b->amax)
        a = dmin(a, 0.5 * b->anb);
    /* so is any segment shorter than a few cycles of travel: the cycles
       after passing into it may be held to its neighbour's acceleration */
    if (b->len < 4 * dmin(b->vmax, b->m.ini_maxvel) * tp->dt + 1e-9)
        a = dmin(a, b->anb);
    r = sqrt(v * v + 2 * PLAN_MARGIN * a * b->len);
    if (b->aplan >= b->amax)
        r = dmax(v, r - b->aplan * tp->dt);
    return r;
}

/* the backward pass from the tail: vend of every segment before it, until
   a value no longer changes (at least `force` segments are recomputed) */
static int back_from(tp_t *tp, int k, int force, int *budget)
{
    int n = 0;
    for (; k >= 0; k--, n++) {
        tc_t *a = seg(tp, k), *b = seg(tp, k + 1);
        double v = dmin(a->cap, dmin(plan_vmax(tp, a), plan_vmax(tp, b)));
        double r = reach_vel(tp, b, b->vend);
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
void backward_pass(tp_t *tp, int force)
{
    int budget = MAX_BACK, k;
    if (tp->count == 0)
        return;
    seg(tp, tp->count - 1)->vend = 0;
    k = back_from(tp, tp->count - 2, force, &budget);
    if (k >= 0) {
        tp->back_slot = slot(tp, k);
        return;
    }
    if (tp->back_slot >= 0) {
        k = (tp->back_slot - tp->head + tp->nslots) % tp->nslots;
        tp->back_slot = -1;
        if (k < tp->count - 1 && budget > 0) {
            k = back_from(tp, k, 1, &budget);
            if (k >= 0)
                tp->back_slot = slot(tp, k);
        }
    }
}
