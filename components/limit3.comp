component limit3 "Follow a signal within position, speed and acceleration limits";

pin in float in "The signal to follow (e.g. a position command)";
pin in bit enable = 1 """TRUE: out follows in. FALSE: out goes back to 0, still
within all the limits""";
pin out float out """in, limited to [min, max], moving at most maxv per second
and changing speed at most maxa per second squared""";
pin in bit load = 0 """While TRUE, out jumps to in (clamped to [min, max])
ignoring maxv and maxa, and the motion state is reset to rest""";
pin in float min_ = -1e20 "Lowest value out may take";
pin in float max_ = 1e20 "Highest value out may take";
pin in float maxv = 1e20 "Largest speed of out, units per second";
pin in float maxa = 1e20 "Largest acceleration of out, units per second squared";
pin in unsigned smooth_steps = 2 """Close to the goal (in, or min/max), when
the gap could be closed within this many periods, brake gradually over
those periods instead of at full maxa. Higher values avoid oscillation
around the goal but arrive a little later; 0 and 1 brake at full maxa""";

variable double vel;        /* speed of out in the last period, units/s */
variable double in_old;     /* the (enabled) input of the last period */

function _ "Move out one period towards the goal";

description """A motion planner for one axis: out chases in, but never
leaves [min, max], never moves faster than maxv and never accelerates faster
than maxa. When the signal is a position, that limits position, velocity and
acceleration.

Each period it either lands on the goal (in clamped to [min, max]) when that
is reachable within the limits, or accelerates or brakes at maxa. It brakes
in time to match the goal's own speed (so a ramp is followed with no
overshoot) and, near the goal, spreads the last braking over up to
smooth-steps periods.

However fast in runs away, out never passes min or max: it moves towards a
bound no faster than lets it stop there at maxa, so it stops exactly at the
bound (LinuxCNC holds this too; its braking profile can differ from this
one by a few periods). Should a change of min or max leave out outside
them, out comes back within maxv and maxa rather than jumping.""";
see_also "limit1(9), limit2(9)";
author "the halsdk authors";
license "GPL";
;;
/* Distance covered while braking from relative speed |dv| to 0 at a,
   one period of speed change per step, after the current period. */
static double brake_dist(double dv, double a, double dt)
{
    double s = fabs(dv);

    if (s <= a * dt)
        return 0;
    return s * (s - a * dt) / (2 * a);
}

/* The fastest speed towards a bound `room` units away (room >= 0) that
   still lets out stop at or before the bound: after this period at
   speed v, each later period is slower by a*dt until 0, so the distance
   is dt * (v + sum over k >= 1 of max(v - k*a*dt, 0)).  With
   v = (n + f)*a*dt (n whole, 0 <= f < 1) that is
   a*dt*dt * (n*(n+1)/2 + f*(n+1)); solve it for v. */
static double stop_speed(double room, double a, double dt)
{
    double unit = a * dt * dt, r, n, f;
    int k;

    if (room <= 0)
        return room / dt;
    if (!(unit > 0))
        return room / dt;
    r = room / unit;
    n = floor((sqrt(8 * r + 1) - 1) / 2);
    /* rounding of the root: keep n*(n+1)/2 <= r < (n+1)*(n+2)/2; a
       step or two at most, and none that could loop for ever where n
       is too large for n + 1 to differ from n (a huge or infinite
       room or limits) */
    for (k = 0; k < 4 && n > 0 && n * (n + 1) / 2 > r; k++)
        n--;
    for (k = 0; k < 4 && (n + 1) * (n + 2) / 2 <= r; k++)
        n++;
    f = (r - n * (n + 1) / 2) / (n + 1);
    if (f > 1)
        f = 1;
    return (n + f) * a * dt;
}

FUNCTION(_) {
    double dt = fperiod;
    double raw, goal, gvel, gv, vlo, vhi, need, over, under, gap, rel, nv, tol;
    double vup, vdown;
    int land = 0, inside_hi, inside_lo;

    /* the goal is the input clamped to [min, max]; its speed is the
       input's own (a clamped goal still "moves" with the input) */
    raw = enable ? in : 0;
    goal = raw;
    if (goal < min_)
        goal = min_;
    if (goal > max_)
        goal = max_;
    gvel = (raw - in_old) / dt;
    in_old = raw;

    if (load) {
        out = goal;
        vel = 0;
        return;
    }

    /* the goal's speed as far as out can follow it */
    gv = gvel;
    if (gv > maxv)
        gv = maxv;
    if (gv < -maxv)
        gv = -maxv;

    /* speeds reachable this period */
    vlo = vel - maxa * dt;
    if (vlo < -maxv)
        vlo = -maxv;
    vhi = vel + maxa * dt;
    if (vhi > maxv)
        vhi = maxv;

    /* land on the goal when it is in reach and the speed change needed
       afterwards (to the goal's speed) is no larger than this one */
    need = (goal - out) / dt;
    if ((need >= vlo && need <= vhi && fabs(gvel - need) <= fabs(need - vel))
        || (fabs(need) < 1e-9 && fabs(vel) < 1e-9 && fabs(gvel) < 1e-9)) {
        /* (the second test ends the endless halving of the last
           smoothed steps once out is within rounding of a goal at rest;
           a goal held at a bound by a moving input is not at rest) */
        nv = need;
        land = 1;
    } else {
        /* where we would end up, relative to the goal moving on at gv, after
           speeding up (over) or slowing down (under) now and then braking */
        rel = vhi - gv;
        over = out + vhi * dt + (rel > 0 ? 1 : -1) * brake_dist(rel, maxa, dt);
        rel = vlo - gv;
        under = out + vlo * dt + (rel > 0 ? 1 : -1) * brake_dist(rel, maxa, dt);

        /* a tie (rounding aside) counts as reachable */
        tol = 1e-12 * fmax(fabs(goal), fabs(out));
        if (over <= goal + tol) {
            nv = vhi;
        } else if (under >= goal - tol) {
            nv = vlo;
        } else {
            /* neither extreme works: brake towards the goal's speed */
            rel = vel - gv;
            nv = rel > 0 ? vlo : vhi;
            /* near the goal, brake over the periods left instead */
            gap = goal - out - gv * dt;
            if (smooth_steps >= 2 && rel != 0 && gap * rel > 0) {
                double t = 2 * gap / (rel * dt);   /* periods to close the gap */

                if (t < smooth_steps) {     /* an exact tie brakes fully */
                    double k = ceil(t);

                    /* unless that would brake harder than maxa anyway */
                    if (fabs(rel / (k * dt)) < maxa)
                        nv = gv + rel * (k - 1) / k;
                }
            }
        }
    }

    /* while out is within [min, max], never faster towards a bound than
       a stop at maxa before it allows: then out can always stop in time,
       and never overshoots a bound whatever the goal does.  (When a
       change of min or max leaves out outside, it comes back within
       maxv and maxa, as in LinuxCNC.) */
    inside_hi = out <= max_;
    inside_lo = out >= min_;
    if (inside_hi) {
        vup = stop_speed(max_ - out, maxa, dt);
        if (nv > vup) {
            nv = vup;
            land = 0;
        }
    }
    if (inside_lo) {
        vdown = -stop_speed(out - min_, maxa, dt);
        if (nv < vdown) {
            nv = vdown;
            land = 0;
        }
    }
    if (land) {
        vel = need;
        out = goal;
        return;
    }
    /* the speed kept is the one out really moved at, rounding included */
    nv = out + nv * dt;
    if (inside_hi && nv > max_)         /* rounding */
        nv = max_;
    if (inside_lo && nv < min_)
        nv = min_;
    vel = (nv - out) / dt;
    out = nv;
}
