/*
 * tp_geom.c - the segments of the trajectory planner (tpmod): the path
 * of a line and of a circle / helix / spiral, its length and unit
 * tangent, and the velocity and acceleration limits that the move and
 * every axis's limits give it ("Limits" at the top of tpmod.c).
 */

#include "tp_priv.h"

/* a line: every axis moves u_i per unit of s */
static void line_limits(const tp_t *tp, tc_t *tc)
{
    int i;
    tc->vmax = tc->m.ini_maxvel;
    tc->amax = tc->m.acc;
    for (i = 0; i < NAX; i++) {
        double f = fabs(tc->u[i]);
        if (f < EPS)
            continue;
        if (tp->ax_vel[i] > 0 && tp->ax_vel[i] / f < tc->vmax)
            tc->vmax = tp->ax_vel[i] / f;
        if (tp->ax_acc[i] > 0 && tp->ax_acc[i] / f < tc->amax)
            tc->amax = tp->ax_acc[i] / f;
    }
}

void line_setup(const tp_t *tp, tc_t *tc)
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
    line_limits(tp, tc);
}

void line_eval(const tc_t *tc, double s, double *p)
{
    int i;
    for (i = 0; i < NAX; i++)
        p[i] = tc->start[i] + tc->u[i] * s;
}

/* limits of a circle/helix/spiral (see the top of tpmod.c); share: the
   part of the acceleration left to the centripetal one (the rest is
   tangential) */
void circle_limits(const tp_t *tp, tc_t *tc, double share)
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
        if (tp->ax_vel[i] > 0 && ti > EPS)
            tc->vmax = dmin(tc->vmax, tp->ax_vel[i] / ti);
        if (tp->ax_acc[i] > 0) {
            if (ti > EPS) {
                tc->amax = dmin(tc->amax, (1 - share) * tp->ax_acc[i] / ti);
                tc->afull = dmin(tc->afull, tp->ax_acc[i] / ti);
            }
            if (ci > EPS) {
                v = sqrt(share * tp->ax_acc[i] / ci);
                tc->vmax = dmin(tc->vmax, v);
                tc->vc = dmin(tc->vc, v);
            }
        }
    }
    for (i = 3; i < NAX; i++) {
        double f = fabs(tc->end[i] - tc->start[i]) / tc->len;
        if (f < EPS)
            continue;
        if (tp->ax_vel[i] > 0)
            tc->vmax = dmin(tc->vmax, tp->ax_vel[i] / f);
        if (tp->ax_acc[i] > 0) {
            tc->amax = dmin(tc->amax, tp->ax_acc[i] / f);
            tc->afull = dmin(tc->afull, tp->ax_acc[i] / f);
        }
    }
}

/* the acceleration segment t allows for speeding up to v: on an arc the
   centripetal part at v is share (v / vc)^2 of each axis's limit at most,
   the rest is free for the tangential part (decelerations keep aplan, which
   the look-ahead plans with) */
double a_up(const tc_t *t, double v)
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

int circle_setup(const tp_t *tp, tc_t *tc, const PmCartesian *center,
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
    circle_limits(tp, tc, 0.5);
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

void tc_eval(const tc_t *tc, double s, double *p)
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
void tc_tangent(const tc_t *tc, int at_end, double *t)
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
