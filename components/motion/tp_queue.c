/*
 * tp_queue.c - the segment queue of the trajectory planner (tpmod):
 * checking a move, adding lines (also probe moves and rigid taps) and
 * circles at the tail (with their junction, blend or merge and the
 * backward pass), taking the head off when it is done, and flushing.
 */

#include "tp_priv.h"

/* where the next queued move starts */
static const double *queue_end(const tp_t *tp)
{
    tc_t *t = tail(tp);
    if (!t)
        return tp->pos;
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

static int check_room(const tp_t *tp, int need, char *why, int whylen)
{
    if (!tp->inited)
        return why_(why, whylen, -ENODEV,
                    "the trajectory planner is not initialized");
    if (tp->aborting)
        return why_(why, whylen, -EBUSY,
                    "the trajectory planner is aborting");
    if (tp->moves >= tp->queue_size || tp->count + need > tp->nslots)
        return why_(why, whylen, -ENOSPC,
                    "the motion queue is full (%d moves)", tp->queue_size);
    return 0;
}

static tc_t *new_tc(tp_t *tp, const tp_move_t *m, int kind, const EmcPose *end)
{
    tc_t *tc = &tp->q[slot(tp, tp->count)];
    const double *st = queue_end(tp);
    int i;

    memset(tc, 0, sizeof(*tc));
    tc->kind = kind;
    tc->m = *m;
    tc->probe_type = -1;
    for (i = 0; i < NAX; i++)
        tc->start[i] = st[i];
    pose_to(end, tc->end);
    tc->seq = tp->next_seq;
    tc->anb = BIG;
    return tc;
}

static void commit_move(tp_t *tp)
{
    tp->next_seq++;
    tp->moves++;
}

/* queue a line (also probes and rigid taps, kind set by the caller) */
int queue_line(tp_t *tp, const EmcPose *end, const tp_move_t *m,
               int probe_type, int rigid, char *why, int whylen)
{
    tc_t *tc, *t;
    double e[NAX];
    int r, i;

    if ((r = check_room(tp, 2, why, whylen)) < 0)
        return r;
    if ((r = check_move(m, why, whylen)) < 0)
        return r;
    if (!end || !finite_pose(end))
        return why_(why, whylen, -EINVAL,
                    "the end point is not a finite number in every axis");
    pose_to(end, e);
    t = tail(tp);
    if (t && probe_type < 0 && !rigid && m->sync == TP_SYNC_NONE &&
        t->kind == TC_LINE && try_merge(tp, t, e, m)) {
        int k = tp->count - 1;
        double nl;
        double d3[3];
        for (i = 0; i < 3; i++)
            d3[i] = e[i] - t->start[i];
        nl = norm3(d3);
        if (can_change(tp, k, nl)) {
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
                line_setup(tp, t);
                t->orig_len = t->len;
                if (tp->count >= 2)
                    junction_setup(tp, seg(tp, tp->count - 2), t);
            }
            set_aplan(tp, t);
            if (tp->count >= 2)
                set_aplan(tp, seg(tp, tp->count - 2));
            tp->qlen += t->len - old_len;
            /* (t keeps its number; the new one is skipped) */
            tp->next_seq++;
            backward_pass(tp, 3);
            return 0;
        }
    }
    tc = new_tc(tp, m, TC_LINE, end);
    if (probe_type >= 0) {
        tc->m.type = TP_MOTION_PROBING;
        tc->probe_type = probe_type;
    }
    tc->rigid = rigid;
    line_setup(tp, tc);
    if (rigid && !(tc->len > 0))
        return why_(why, whylen, -EINVAL,
                    "a rigid tap needs a nonzero length");
    for (i = 0; i < 3; i++)
        tc->orig_start[i] = tc->start[i];
    tc->orig_len = tc->len;
    if (t && tc->len > 0) {
        /* t's end changes only when a blend is inserted */
        if (insert_blend(tp, t, tc)) {
            tc_t *arc = &tp->q[slot(tp, tp->count)];
            tc_t *nb = &tp->q[slot(tp, tp->count + 1)];
            tp->count += 2;
            tp->qlen += arc->len + nb->len;
            set_aplan(tp, t);
            set_aplan(tp, arc);
            set_aplan(tp, nb);
            nb->cap = 0;
            commit_move(tp);
            backward_pass(tp, 4);
            return 0;
        }
        junction_setup(tp, t, tc);
        set_aplan(tp, t);
    }
    tc->cap = 0;
    set_aplan(tp, tc);
    tp->count++;
    tp->qlen += tc->len;
    commit_move(tp);
    backward_pass(tp, 3);
    return 0;
}

int queue_circle(tp_t *tp, const EmcPose *end, const PmCartesian *center,
                 const PmCartesian *normal, int turn,
                 const tp_move_t *m, char *why, int whylen)
{
    tc_t *tc, *t;
    int r;

    if ((r = check_room(tp, 1, why, whylen)) < 0)
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
    t = tail(tp);
    tc = new_tc(tp, m, TC_CIRCLE, end);
    if ((r = circle_setup(tp, tc, center, normal, turn, why, whylen)) < 0)
        return r;
    tc->orig_len = tc->len;
    if (t) {
        junction_setup(tp, t, tc);
        set_aplan(tp, t);
    }
    tc->cap = 0;
    set_aplan(tp, tc);
    tp->count++;
    tp->qlen += tc->len;
    commit_move(tp);
    backward_pass(tp, 3);
    return 0;
}

void flush_queue(tp_t *tp)
{
    tp->head = 0;
    tp->count = 0;
    tp->qlen = 0;
    tp->back_slot = -1;
    tp->moves = 0;
    tp->started = 0;
    tp->s = tp->v = tp->a = tp->ja = 0;
    tp->ev_head = tp->ev_count = 0;
    tp->aborting = 0;
    tp->pausing = 0;
    tp->stepping = 0;
    tp->resume_after_step = 0;
    tp->waiting = 0;
    tp->sync_started = 0;
    tp->corner_prev = tp->corner_now = 0;
    if (tp->rt_reversed && tp->hooks.spindle_reverse)
        tp->hooks.spindle_reverse(tp->rt_spindle, 0);
    tp->rt_reversed = 0;
}

/* the head segment is done */
void pop_tc(tp_t *tp)
{
    tc_t *t = seg(tp, 0);
    int last_of_move = tp->count < 2 || seg(tp, 1)->seq != t->seq;
    tp->head = (tp->head + 1) % tp->nslots;
    tp->count--;
    tp->qlen = tp->count ? tp->qlen - t->len : 0;
    if (last_of_move && tp->moves > 0)
        tp->moves--;
    tp->started = 0;
    tp->s = 0;
    tp->sync_started = 0;
    tp->waiting = 0;
    if (tp->stepping && last_of_move && t->seq == tp->step_seq) {
        tp->stepping = 0;
        tp->pausing = !tp->resume_after_step;
        tp->resume_after_step = 0;
    }
}
