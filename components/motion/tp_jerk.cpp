/*
 * tp_jerk.cpp - jerk-limited steps of the path parameter for tpmod
 * (tp_jerk.h), computed by ruckig in one degree of freedom.
 *
 * tpmod asks, each cycle of a move with a jerk limit, where the path
 * parameter would be after one cycle if it followed the time-optimal
 * jerk-limited profile from its present state (velocity, acceleration)
 * either to a velocity (velocity interface) or to a point at a given
 * velocity (position interface: the next junction or stop).  ruckig's
 * calculate() keeps no state between calls; the Ruckig object and the
 * trajectory are static, with a fixed number of degrees of freedom, so
 * nothing is allocated; with exceptions off, failures are result codes.
 */

#include <cmath>

#include <ruckig/ruckig.hpp>

#include "tp_jerk.h"

namespace {

typedef ruckig::Ruckig<1, ruckig::StandardVector, false> planner_t;

planner_t rk(0.001);
ruckig::InputParameter<1> in;
ruckig::Trajectory<1> traj;

/* ruckig fails on a few inputs for numerical reasons; lowering the
   limits by a hair then works (as in freeplan_jerk.cpp) */
const double SHAVE[] = {1.0, 1.0 - 1e-9, 1.0 - 1e-6, 1.0 - 1e-4};

} // namespace

extern "C" int tp_jerk_step(int position, double dist, double vf,
                            double v0, double a0, double vmax,
                            double amax, double jmax, double dt,
                            double *p, double *v, double *a)
{
    if (!(dt > 0.0 && amax > 0.0 && jmax > 0.0 && vmax >= 0.0)
        || !std::isfinite(v0) || !std::isfinite(a0)
        || !std::isfinite(dist) || !std::isfinite(vf))
        return -1;
    in.control_interface = position ? ruckig::ControlInterface::Position
                                    : ruckig::ControlInterface::Velocity;
    in.current_position[0] = 0.0;
    in.current_velocity[0] = v0;
    in.current_acceleration[0] = a0;
    in.target_position[0] = position ? dist : 0.0;
    in.target_velocity[0] = vf;
    in.target_acceleration[0] = 0.0;
    in.max_velocity[0] = vmax;
    in.min_velocity = std::nullopt;
    for (double f : SHAVE) {
        in.max_acceleration[0] = amax * f;
        in.max_jerk[0] = jmax * f;
        ruckig::Result r = rk.calculate(in, traj);
        if (r != ruckig::Result::Working && r != ruckig::Result::Finished)
            continue;
        std::array<double, 1> pp, vv, aa;
        if (traj.get_duration() <= dt) {
            /* over within this cycle: at the goal */
            pp[0] = position ? dist : 0.0;
            vv[0] = vf;
            aa[0] = 0.0;
            if (!position) {
                /* (velocity interface: the distance of the cycle) */
                traj.at_time(traj.get_duration(), pp, vv, aa);
                pp[0] += vf * (dt - traj.get_duration());
                vv[0] = vf;
                aa[0] = 0.0;
            }
        } else {
            traj.at_time(dt, pp, vv, aa);
        }
        if (!std::isfinite(pp[0]) || !std::isfinite(vv[0])
            || !std::isfinite(aa[0]))
            return -1;
        *p = pp[0];
        *v = vv[0];
        *a = aa[0];
        return 0;
    }
    return -1;
}
