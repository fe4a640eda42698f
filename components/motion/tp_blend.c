/*
 * tp_blend.c - corner blends and merges of the trajectory planner
 * (tpmod): a tangent arc in place of the corner between two lines
 * (TP_TERM_BLEND, G64 P), consecutive lines merged into one (naive CAM,
 * G64 Q), and whether a queued segment may still be shortened without
 * breaking the velocity profile the planner follows now.
 */

#include "tp_priv.h"

/* distance from the present position to the start of queued segment k */
static double dist_to(const tp_t *tp, int k)
{
    double d = 0;
    int j;
    if (k == 0)
        return 0;
    d = seg(tp, 0)->len - tp->s;
    for (j = 1; j < k && d < 1e300; j++)
        d += seg(tp, j)->len;
    return d;
}

/* may segment k (ahead) be changed (shortened) without breaking the
   velocity profile the planner may be following now? */
int can_change(const tp_t *tp, int k, double new_len)
{
    double v = tp->v, a, need;
    tc_t *t = seg(tp, k);
    if (k == 0 && tp->started && tp->s >= new_len)
        return 0;
    if (v <= 0)
        return 1;
    a = dmax(t->aplan * 0.5, 1e-9);
    need = v * v / (2 * a) + 4 * v * tp->dt;
    if (k == 0)
        return new_len - tp->s > need;
    if (k == tp->count - 1)         /* the tail: from the running total */
        return tp->qlen - tp->s - t->len > need;
    return dist_to(tp, k) > need;
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
int insert_blend(tp_t *tp, tc_t *a, tc_t *b)
{
    double c1 = dot3(a->u, b->u), alpha, half, d, R, tol, nv[3], pc[3];
    double nrm[3], nn, e0[3];
    tc_t *arc, tmp;
    int i, ka = tp->count - 1;

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
    if (exact_cap(tp, a, b) >= dmin(plan_vmax(tp, a), plan_vmax(tp, b)))
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
    if (!can_change(tp, ka, a->len - d))
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
    circle_limits(tp, arc, BLEND_SHARE);
    /* the arc is at most as fast as either line's move allows */
    arc->vmax = dmin(arc->vmax, dmax(a->vmax, tmp.vmax));
    /* trim a */
    for (i = 0; i < 3; i++)
        a->end[i] = arc->start[i];
    a->len -= d;
    tp->qlen -= d;
    a->trimmed_out = 1;
    /* b one slot on, trimmed */
    {
        tc_t *nb = &tp->q[slot(tp, tp->count + 1)];
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
int try_merge(const tp_t *tp, tc_t *t, const double *end, const tp_move_t *m)
{
    double q = m->cam_tolerance, d[3], L, nd[3];
    int i, k;

    if (q <= 0 || m->term_cond != TP_TERM_BLEND ||
        t->m.term_cond != TP_TERM_BLEND || !xyz_only_line(t) ||
        t->trimmed_out || t->npts >= CAM_PTS || tp->count < 1)
        return 0;
    if (t->m.type != m->type || t->m.vel != m->vel ||
        t->m.acc != m->acc || t->m.ini_maxvel != m->ini_maxvel ||
        t->m.flags != m->flags || t->m.cam_tolerance != q)
        return 0;
    if (tp->count == 1 && tp->started)
        return 0;
    for (i = 3; i < NAX; i++)
        if (fabs(end[i] - t->end[i]) > EPS)
            return 0;
    /* a synchronized output waits for the start of the new move */
    if (tp->ev_count > 0 &&
        tp->ev[(tp->ev_head + tp->ev_count - 1) % NSYNC].seq == tp->next_seq)
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
