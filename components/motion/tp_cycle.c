/*
 * tp_cycle.c - one cycle of the trajectory planner (tpmod): the velocity
 * each segment asks for (feed and rapid scale, adaptive feed, feed hold
 * and inhibit, pause, abort), the walk over the junctions ahead and the
 * velocity of this cycle, the jerk-limited profile, the advance along the
 * path, spindle-synchronized moves and rigid taps, probing, and the
 * synchronized outputs fired when a move starts.
 */

#include "tp_priv.h"
#include "tp_jerk.h"

/* the velocity segment t asks for now; plain: without pause, abort, feed
   hold and feed inhibit (those only make the head decelerate) */
static double want_vel_(const tp_t *tp, const tc_t *t, int plain)
{
    double v = t->m.vel;
    if (t->m.sync == TP_SYNC_VELOCITY) {
        double sp = (tp->in.have & TP_IN_SPINDLES)
            ? tp->in.spindle[t->m.spindle].speed : tp->in.spindle_speed;
        v = t->m.pitch * fabs(isfinite(sp) ? sp : 0);
    }
    if (!(t->m.flags & TP_MOVE_NO_FEED_SCALE))
        v *= t->m.type == TP_MOTION_TRAVERSE ? tp->rapid_scale : tp->in_feed;
    if (!plain && tp->in_inhibit)
        v = 0;
    if (!plain && tp->in_hold && !(t->m.flags & TP_MOVE_NO_FEED_HOLD))
        v = 0;
    if (v > t->vmax)
        v = t->vmax;
    if (t->m.ini_maxvel < v)
        v = t->m.ini_maxvel;
    if (tp->vel_limit > 0 && v > tp->vel_limit)
        v = tp->vel_limit;
    if (!plain && (tp->aborting || tp->pausing))
        v = 0;
    return v;
}

static double want_vel(const tp_t *tp, const tc_t *t)
{
    return want_vel_(tp, t, 0);
}

/* the junction at the end of segment k must be passed at rest */
static int stop_at_end(const tp_t *tp, int k)
{
    tc_t *t = seg(tp, k);
    if (k >= tp->count - 1 || t->cap <= 0)
        return 1;
    if (tp->stepping && t->seq == tp->step_seq &&
        seg(tp, k + 1)->seq != t->seq)
        return 1;
    return 0;
}

static void finish_probe(tp_t *tp, tc_t *tc)
{
    if (tc->probe_type >= 0 && tp->probe_result == 0) {
        tp->probe_result = -1;
        if (!(tc->probe_type & TP_PROBE_NO_ERROR)) {
            set_error(tp, "the probe move ended without contact");
            tp->aborting = 1;
        }
    }
}

static void fire_sync(tp_t *tp, unsigned long seq)
{
    while (tp->ev_count > 0) {
        sync_ev_t *e = &tp->ev[tp->ev_head];
        if ((long)(e->seq - seq) > 0)
            break;
        if (e->analog && tp->hooks.set_aout)
            tp->hooks.set_aout(e->index, e->value);
        else if (!e->analog && tp->hooks.set_dout)
            tp->hooks.set_dout(e->index, (int)e->value);
        tp->ev_head = (tp->ev_head + 1) % NSYNC;
        tp->ev_count--;
    }
}

static int start_tc(tp_t *tp, const tp_inputs_t *in)
{
    tc_t *tc = seg(tp, 0);
    tp->started = 1;
    tp->exec_id = tc->m.id;
    tp->motion_type = tc->m.type;
    fire_sync(tp, tc->seq);
    if (tc->probe_type >= 0) {
        int tripped = in ? ((tc->probe_type & TP_PROBE_AWAY)
                            ? !in->probe_input : in->probe_input != 0) : 0;
        tp->probe_result = 0;
        if (tripped) {
            set_error(tp, "the probe is already tripped when the probe "
                      "move starts");
            flush_queue(tp);
            return -1;
        }
    }
    return 0;
}

static double spindle_revs(const tp_t *tp, int n)
{
    double r = (tp->in.have & TP_IN_SPINDLES) ? tp->in.spindle[n].revs
                                             : tp->in.spindle_revs;
    return isfinite(r) ? r : 0;
}

/* a position-synchronized move or rigid tap at the head; returns 1 while
   it is in charge of the cycle */
static int run_synced(tp_t *tp, tc_t *tc)
{
    int n = tc->m.spindle;
    double s_old = tp->s, s;

    if (!tp->sync_started) {
        int at_speed = (tp->in.have & TP_IN_SPINDLES)
            ? tp->in.spindle[n].at_speed : tp->in.spindle_at_speed;
        if (tp->aborting) {
            flush_queue(tp);
            return 1;
        }
        if (tp->in_inhibit || tp->pausing) {
            tp->waiting = 0;
            return 1;
        }
        if (tp->waiting == 0) {
            tp->waiting = 1;
        }
        if (tp->waiting == 1) {
            if (!at_speed)
                return 1;
            if (tp->hooks.index_enable && (tp->in.have & TP_IN_SPINDLES)) {
                tp->hooks.index_enable(n);
                tp->waiting = 2;
                return 1;
            }
        } else if (tp->waiting == 2) {
            if (tp->in.spindle[n].index_enable)
                return 1;
        }
        tp->waiting = 0;
        tp->sync_started = 1;
        tp->revs0 = spindle_revs(tp, n);
        tp->rt_phase = RT_TAPPING;
        tp->rt_smin = tp->rt_smax = 0;
        return 1;
    }
    s = tc->m.pitch * (spindle_revs(tp, n) - tp->revs0);
    if (!tc->rigid) {
        /* G33: forward only, to the end */
        s = fabs(s);
        if (s >= tc->len) {
            tp->s = tc->len;
            tc_eval(tc, tp->s, tp->pos);
            tp->v = 0;
            pop_tc(tp);
            return 1;
        }
        if (s < s_old)
            s = s_old;
        tp->s = s;
        tp->v = (s - s_old) / tp->dt;
        line_eval(tc, s, tp->pos);
        return 1;
    }
    switch (tp->rt_phase) {
    case RT_TAPPING:
        if (s >= tc->len) {
            tp->hooks.spindle_reverse(n, 1);
            tp->rt_reversed = 1;
            tp->rt_spindle = n;
            tp->rt_phase = RT_REVERSING;
            tp->rt_smax = s;
        }
        break;
    case RT_REVERSING:
        if (s > tp->rt_smax)
            tp->rt_smax = s;
        else if (s < tp->rt_smax - 1e-12)
            tp->rt_phase = RT_RETRACTING;
        break;
    case RT_RETRACTING:
        if (s <= 0) {
            tp->hooks.spindle_reverse(n, 0);
            tp->rt_reversed = 0;
            tp->rt_phase = RT_FINAL;
            tp->rt_smin = s;
        }
        break;
    case RT_FINAL:
        if (s < tp->rt_smin) {
            tp->rt_smin = s;
        } else if (s > tp->rt_smin + 1e-12) {
            tp->rt_phase = RT_PLACING;
            s = s_old;
            tp->v = 0;
        }
        break;
    default:
        break;
    }
    if (tp->rt_phase == RT_PLACING) {
        /* back to the start under the move's acceleration */
        double left = -s_old, nv;
        double dir = left > 0 ? 1 : -1;
        double a = tc->amax;
        left = fabs(left);
        nv = dmin(fabs(tp->v) + a * tp->dt, stop_vel(left, a, tp->dt));
        nv = dmin(nv, tc->vmax);
        if (left - nv * tp->dt <= 1e-12) {
            tp->s = 0;
            line_eval(tc, 0, tp->pos);
            tp->v = 0;
            tp->hooks.spindle_reverse(n, 0);
            pop_tc(tp);
            return 1;
        }
        tp->s = s_old + dir * nv * tp->dt;
        tp->v = dir * nv;
        line_eval(tc, tp->s, tp->pos);
        return 1;
    }
    tp->s = s;
    tp->v = (s - s_old) / tp->dt;
    line_eval(tc, s, tp->pos);
    return 1;
}

/* one cycle of ordinary (planned) motion at the head */
static void run_planned(tp_t *tp, const tp_inputs_t *in)
{
    double dt = tp->dt, lim = BIG, lim_hard, dist, arun, acyc;
    double vt, nv, lo, hi, step, moved = 0;
    int k, tripped, nw = 0, step_tries = 0, step_probe = 0;
    double soft = BIG;
    tc_t *tc = seg(tp, 0);
    tp_walk_t *wk = tp->wk;

    /* probing: contact stops the move and records the position of the
       cycle the input changed in */
    if (tc->probe_type >= 0 && in && !tp->aborting && tp->probe_result == 0) {
        tripped = (tc->probe_type & TP_PROBE_AWAY) ? !in->probe_input
                                                  : in->probe_input != 0;
        if (tripped) {
            memcpy(tp->probe_pos, tp->pos, sizeof(tp->probe_pos));
            tp->probe_result = 1;
            tp->aborting = 1;
        }
    }

    /* the acceleration of this cycle: the head's; after a cycle that
       passed a junction, the one that cycle had (see below) */
    acyc = tc->aplan;
    if (tp->corner_prev)
        acyc = dmin(acyc, tp->a_after);
    vt = want_vel(tp, tc);
    tp->reqv = vt;
    {
        double au = a_up(tc, tp->v + a_up(tc, tp->v) * dt);
        if (tp->corner_prev)
            au = dmin(au, tp->a_after_up);
        hi = tp->v + dmax(acyc, au) * dt;
    }
    lo = tp->v - acyc * dt;
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
        double vhi = tp->v + acyc * dt, amin = tc->aplan, horizon;
        dist = tc->len - tp->s;
        tp->active = 1;
        for (k = 0; k < tp->count && k < MAX_WALK; k++) {
            tc_t *t = seg(tp, k);
            int stop = stop_at_end(tp, k);
            if (k > 0) {
                amin = dmin(amin, t->aplan);
                if (dist - t->len < nv * dt)
                    tp->active = k + 1;
            }
            wk[k].dist = dist;
            wk[k].stop = stop;
            wk[k].vf = stop ? 0 : dmin(t->vend, t->cap);
            wk[k].ws = stop ? 0 : want_vel_(tp, seg(tp, k + 1), 1);
            nw = k + 1;
            if (stop)
                break;
            horizon = 2 * vhi * dt + vhi * vhi / (2 * PLAN_MARGIN * amin);
            if (dist > horizon)
                break;
            dist += seg(tp, k + 1)->len;
        }
        /* backward over the walked junctions: the velocity at junction
           k from its own limit and, with a margin on the acceleration,
           from those after it (continuous: it composes exactly; the
           discrete staircase toward the first one, below, stays under
           the continuous one by less than one step, which is taken off
           when the composed value binds) */
        wk[nw - 1].composed = 0;
        for (k = nw - 2; k >= 0; k--) {
            tc_t *b = seg(tp, k + 1);
            double r = reach_vel(tp, b, wk[k + 1].vf);
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
            tc_t *t = seg(tp, k);
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
            ax = dmin(arun, seg(tp, k + 1)->aplan);
            if (t->corner_out)
                ax = dmin(ax, 0.5 * dmin(t->amax, seg(tp, k + 1)->amax));
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
        tp->stepping = 1;
        step_probe = 0;
        if (lim >= lo - 1e-9 * (1 + tp->v)) {
            int j;
            for (j = 0; j < tp->count - 1 && j < MAX_WALK; j++)
                if ((long)(seg(tp, j)->seq - tp->step_seq) > 0) {
                    tp->step_seq = seg(tp, j)->seq;
                    break;
                }
        } else {
            step_tries = 99;
        }
        goto step_again;
    }
    /* the first cycle after STEP: can the machine still stop at the end
       of the move?  (at most a few moves on; a few walks, once) */
    if (tp->stepping && tp->step_new && lim < lo - 1e-9 * (1 + tp->v) &&
        step_tries++ < 6) {
        tp->stepping = 0;
        step_probe = 1;
        goto step_again;
    }
    /* the step's stop is decided in the first cycle after STEP, from then
       on the machine stops there like at any other stop */
    if (tp->stepping)
        tp->step_new = 0;
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
    tp->corner_now = 0;
    {
        double d2 = tc->len - tp->s, ax = tc->aplan, am = tc->amax;
        double axu = a_up(tc, nv);
        int corner = 0, crossed = 0;
        for (k = 0; k + 1 < tp->count && k < MAX_WALK && nv * dt >= d2; k++) {
            if (stop_at_end(tp, k))
                break;
            crossed = 1;
            ax = dmin(ax, seg(tp, k + 1)->aplan);
            axu = dmin(axu, a_up(seg(tp, k + 1), nv));
            am = dmin(am, seg(tp, k + 1)->amax);
            if (seg(tp, k)->corner_out)
                corner = 1;
            d2 += seg(tp, k + 1)->len;
        }
        if (crossed) {
            /* (aplan of a short segment next to a corner is half already) */
            if (corner) {
                ax = dmin(ax, 0.5 * am);
                axu = dmin(axu, 0.5 * am);
            }
            axu = dmax(axu, ax);
            {
                double h2 = tp->v + axu * dt, l2 = tp->v - ax * dt;
                if (nv > h2)
                    nv = h2;
                /* (a soft limit never asks for more than that) */
                if (nv < l2)
                    nv = dmin(l2, lim_hard);
            }
            tp->corner_now = 1;
            tp->a_after = ax;
            tp->a_after_up = axu;
        }
    }

    /* jerk-limited moves: the time-optimal jerk-limited profile toward the
       requested velocity and toward the next junctions (ruckig), the
       most restrictive; the staircase above when none is found */
    step = nv * dt;
    if (tc->m.jerk > 0) {
        double J = tc->m.jerk, A = tc->amax, bp = BIG, bv = 0, ba = 0;
        double p, v, a, vmx = dmax(vt, tp->v);
        int ok = 0;
        if (tp_jerk_step(0, 0, vt, tp->v, tp->ja, vmx + 1, A, J, dt,
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
            if (tp_jerk_step(1, wk[k].dist, vf, tp->v, tp->ja,
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
            tp->ja = ba;
            /* never past a stop the profiles did not look at */
            for (k = 0; k < nw; k++)
                if (wk[k].stop) {
                    if (step > wk[k].dist)
                        step = wk[k].dist;
                    break;
                }
        } else {
            tp->ja = (nv - tp->v) / dt;
        }
    } else {
        tp->ja = 0;
    }

    /* advance */
    for (;;) {
        double rem;
        tc = seg(tp, 0);
        rem = tc->len - tp->s;
        if (step < rem - (stop_at_end(tp, 0) ? EPS * (1 + tc->len) : 0)) {
            tp->s += step;
            moved += step;
            tc_eval(tc, tp->s, tp->pos);
            break;
        }
        if (stop_at_end(tp, 0)) {
            /* land exactly on the end and rest */
            moved += rem;
            tp->s = tc->len;
            tc_eval(tc, tp->s, tp->pos);
            finish_probe(tp, tc);
            pop_tc(tp);
            nv = 0;
            tp->ja = 0;
            if (tp->aborting)
                flush_queue(tp);
            break;
        }
        step -= rem;
        moved += rem;
        pop_tc(tp);
        if (tp->count == 0)
            break;
        start_tc(tp, in);
        if (tp->count == 0)
            break;
    }
    tp->a = (nv - tp->v) / dt;
    tp->v = nv;
    tp->corner_prev = tp->corner_now;
    (void)moved;
    if (tp->aborting && tp->v == 0)
        flush_queue(tp);
}

void run_cycle(tp_t *tp, const tp_inputs_t *in, EmcPose *out)
{
    double prev[NAX], dt = tp->dt;
    int i;
    tc_t *tc;

    for (i = 0; i < NAX; i++)
        prev[i] = tp->pos[i];
    if (in)
        tp->in = *in;
    else
        memset(&tp->in, 0, sizeof(tp->in));
    if (tp->in.have & TP_IN_FEED) {
        double af = tp->in.adaptive_feed;
        if (!(af >= 0))
            af = 0;
        if (af > 1)
            af = 1;
        tp->in_feed = tp->feed_scale * af;
        tp->in_hold = tp->in.feed_hold != 0;
        tp->in_inhibit = tp->in.feed_inhibit != 0;
    } else {
        tp->in_feed = tp->feed_scale;
        tp->in_hold = tp->in_inhibit = 0;
    }
    tp->reqv = 0;
    tp->active = 0;
    if (!tp->inited || tp->count == 0) {
        tp->v = tp->a = 0;
        tp->aborting = 0;
        goto out;
    }
    tc = seg(tp, 0);
    if (tc->m.sync == TP_SYNC_POSITION && !(tp->aborting && tp->v != 0 &&
                                           !tc->rigid)) {
        if (!tp->started) {
            if (tp->aborting) {
                flush_queue(tp);
                goto out;
            }
            if (tp->pausing && !tp->stepping)
                goto out;
            if (start_tc(tp, in) < 0)
                goto out;
        }
        tp->active = 1;
        run_synced(tp, tc);
        goto out;
    }
    if (!tp->started) {
        if (tp->aborting || (tp->pausing && !tp->stepping)) {
            tp->v = tp->a = 0;
            if (tp->aborting)
                flush_queue(tp);
            goto out;
        }
        if (start_tc(tp, in) < 0)
            goto out;
        if (tp->v == 0) {
            /* rest this cycle: the previous move ended at rest, and a
               cycle at rest between moves keeps the sampled acceleration
               within the limits where the direction changes */
            tp->a = 0;
            goto out;
        }
    }
    run_planned(tp, in);
out:
    for (i = 0; i < NAX; i++)
        tp->last_vel[i] = (tp->pos[i] - prev[i]) / (dt > 0 ? dt : 1);
    if (out)
        to_pose(tp->pos, out);
}
