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
smooth-steps periods.""";
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

FUNCTION(_) {
    double dt = fperiod;
    double raw, goal, gvel, gv, vlo, vhi, need, over, under, gap, rel, nv, tol;

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
        || (fabs(need) < 1e-9 && fabs(vel) < 1e-9)) {
        /* (the second test ends the endless halving of the last
           smoothed steps once out is within rounding of the goal) */
        vel = need;
        out = goal;
        return;
    }

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
    /* the speed kept is the one out really moved at, rounding included */
    nv = out + nv * dt;
    vel = (nv - out) / dt;
    out = nv;
}
