/*
 * mot_comp.c - backlash and lead-screw compensation of one joint (see
 * mot_comp.h).  Realtime: no allocation, no locks; the filter is the
 * free planner's trapezoid (freeplan.c), which needs no fp_init().
 */

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mot_comp.h"

static int refuse(char *why, int len, const char *text)
{
    if (why && len > 0)
        snprintf(why, len, "%s", text);
    return -EINVAL;
}

void mot_comp_init(mot_comp_t *c)
{
    memset(c, 0, sizeof(*c));
    fp_reset(&c->filt, 0.0);
    c->filt.profile = FP_TRAPEZOID;
}

void mot_comp_clear(mot_comp_t *c)
{
    c->entries = 0;
}

int mot_comp_add(mot_comp_t *c, double nominal, double fwd_trim,
                 double rev_trim, char *why, int len)
{
    int n = c->entries;

    if (!isfinite(nominal))
        return refuse(why, len, "nominal position is not a finite number");
    if (!isfinite(fwd_trim) || !isfinite(rev_trim))
        return refuse(why, len, "trims must be finite numbers");
    if (n >= MOT_COMP_SIZE)
        return refuse(why, len, "compensation table is full "
                      "(256 entries at most)");
    if (n > 0 && !(nominal > c->table[n - 1].nominal)) {
        if (why && len > 0)
            snprintf(why, len, "entry %d: nominal position must be greater "
                     "than the one of entry %d", n + 1, n);
        return -EINVAL;
    }
    c->table[n].nominal = nominal;
    c->table[n].fwd_trim = fwd_trim;
    c->table[n].rev_trim = rev_trim;
    c->entries = n + 1;
    return 0;
}

int mot_comp_set_backlash(mot_comp_t *c, double backlash, char *why,
                          int len)
{
    if (!isfinite(backlash) || backlash < 0.0)
        return refuse(why, len, "backlash must be a finite number >= 0");
    c->backlash = backlash;
    return 0;
}

static double trim_of(const mot_comp_entry_t *e, int dir)
{
    if (dir > 0)
        return e->fwd_trim;
    if (dir < 0)
        return e->rev_trim;
    return 0.5 * (e->fwd_trim + e->rev_trim);
}

double mot_comp_lookup(const mot_comp_t *c, double pos, int dir)
{
    const mot_comp_entry_t *t = c->table;
    int n = c->entries, lo, hi, mid;
    double a, b;

    if (n <= 0 || n > MOT_COMP_SIZE)
        return 0.0;
    if (!(pos > t[0].nominal))      /* also NaN */
        return trim_of(&t[0], dir);
    if (pos >= t[n - 1].nominal)
        return trim_of(&t[n - 1], dir);
    /* t[lo].nominal <= pos < t[hi].nominal */
    lo = 0;
    hi = n - 1;
    while (hi - lo > 1) {
        mid = (lo + hi) / 2;
        if (t[mid].nominal <= pos)
            lo = mid;
        else
            hi = mid;
    }
    a = trim_of(&t[lo], dir);
    b = trim_of(&t[hi], dir);
    return a + (b - a) * (pos - t[lo].nominal)
        / (t[hi].nominal - t[lo].nominal);
}

void mot_comp_update(mot_comp_t *c, double pos_cmd, double vel_cmd,
                     double dt, double max_vel, double max_acc,
                     double *corr, double *filt, double *filt_vel)
{
    double vl = max_vel * MOT_COMP_VEL_SHARE;
    double al = max_acc * MOT_COMP_ACC_SHARE;

    /* the direction of the commanded motion; at rest it stays */
    if (vel_cmd > 0.0)
        c->dir = 1;
    else if (vel_cmd < 0.0)
        c->dir = -1;
    if (isfinite(pos_cmd)) {
        if (c->entries > 0)
            c->corr = mot_comp_lookup(c, pos_cmd, c->dir);
        else
            c->corr = 0.5 * c->backlash * c->dir;
    }
    if (dt > 0.0 && isfinite(dt)) {
        if (vl > 0.0 && al > 0.0 && isfinite(vl) && isfinite(al)) {
            c->filt.target = c->corr;
            c->filt.max_vel = vl;
            c->filt.max_acc = al;
            c->filt.profile = FP_TRAPEZOID;
            c->filt.enable = 1;
            fp_update(&c->filt, dt);
        } else {
            /* no limits to respect: at once */
            fp_reset(&c->filt, c->corr);
        }
    }
    *corr = c->corr;
    *filt = c->filt.pos;
    *filt_vel = c->filt.vel;
}
