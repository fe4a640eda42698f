/*
 * freeplan_jerk.cpp - the jerk-limited profile of the free planner
 * (freeplan.h, FP_JERK), computed by ruckig.
 *
 * One ruckig::Ruckig<1> per planner, allocated by fp_init() at load time.
 * Every cycle the planner's own state (pos, vel, acc) and the target go
 * in as ruckig's input; while neither they nor the limits change, ruckig
 * keeps sampling the trajectory it has, otherwise it computes a new one
 * from the present state, so new targets and lower limits never make a
 * step in position, velocity or acceleration.  A stop (enable = 0) uses
 * ruckig's velocity interface toward zero velocity and acceleration, and
 * so does the descent onto a lowered velocity limit (freeplan.c decides).
 *
 * Realtime: with a fixed number of degrees of freedom ruckig keeps all
 * its data in std::array, and with throw_error = false it reports
 * problems by result codes; fp_jerk_update() allocates nothing, takes no
 * lock and catches nothing.
 */

#include <cfloat>
#include <cmath>
#include <new>

#include <ruckig/ruckig.hpp>

#include "freeplan.h"

namespace {

typedef ruckig::Ruckig<1, ruckig::StandardVector, false> planner_t;

/* ruckig refuses trajectories longer than about 7600 s; longer moves go
   through intermediate targets this many seconds of max_vel apart */
const double FP_SUB_SECONDS = 1000.0;

struct jerk_state {
    planner_t rk;
    ruckig::InputParameter<1> in;
    ruckig::OutputParameter<1> out;
    double sub;                 /* intermediate target of a long move */
    bool sub_valid;
    int shave;                  /* index in FP_SHAVE that works */

    jerk_state() : rk(0.001), sub(0.0), sub_valid(false), shave(0) {
        in.target_velocity[0] = 0.0;
        in.target_acceleration[0] = 0.0;
    }
};

/* ruckig's step 1 fails on a few inputs for numerical reasons (e.g.
   0.263 at 30/s, 26444/s^2, 1.7e8/s^3); the same input with the
   acceleration and jerk limits lowered by a hair then works.  These are
   the factors tried in turn; the one that worked is kept. */
const double FP_SHAVE[][2] = {          /* acceleration, jerk */
    {1.0, 1.0}, {1.0 - 1e-9, 1.0}, {1.0 - 1e-6, 1.0 - 1e-6},
    {1.0 - 1e-4, 1.0 - 1e-4}
};
const int FP_NSHAVE = sizeof(FP_SHAVE) / sizeof(FP_SHAVE[0]);

/* ruckig's trajectories are not always sound for tiny, fast moves
   (durations of a few cycles, jerk limits of 1e7 and more, targets
   changed every cycle): a step from (fp->pos, vel, acc) to (p, v, a)
   in dt must keep the limits (beyond rounding) or it is refused */
bool plausible(const freeplan_t *fp, double p, double v, double a,
               double dt)
{
    const double tol = 1e-6;
    double v0 = std::fabs(fp->vel), a0 = std::fabs(fp->acc);
    double vlim = std::fmax(fp->max_vel, v0 + a0 * dt) * (1.0 + tol);
    double alim = std::fmax(fp->max_acc, a0) * (1.0 + tol);

    if (std::fabs(a - fp->acc) > fp->max_jerk * dt * (1.0 + tol))
        return false;
    if (std::fabs(a) > alim || std::fabs(v) > vlim)
        return false;
    /* the mean velocity over the cycle */
    if (std::fabs(p - fp->pos) > vlim * dt
        + 4.0 * DBL_EPSILON * (std::fabs(p) + std::fabs(fp->pos)))
        return false;
    return true;
}

/* one ruckig cycle toward the position goal, or (stop) toward the
   velocity vgoal; true when the planner state was advanced */
bool jerk_step(jerk_state *j, freeplan_t *fp, double goal, bool stop,
               double vgoal)
{
    ruckig::InputParameter<1> &in = j->in;

    in.control_interface = stop ? ruckig::ControlInterface::Velocity
                                : ruckig::ControlInterface::Position;
    in.current_position[0] = fp->pos;
    in.current_velocity[0] = fp->vel;
    in.current_acceleration[0] = fp->acc;
    if (!stop)
        in.target_position[0] = goal;
    in.target_velocity[0] = stop ? vgoal : 0.0;
    in.target_acceleration[0] = 0.0;
    in.max_velocity[0] = fp->max_vel > 0.0 ? fp->max_vel : 0.0;
    ruckig::Result r = ruckig::Result::Error;
    for (int k = 0; k < FP_NSHAVE; k++) {
        int i = (j->shave + k) % FP_NSHAVE;

        in.max_acceleration[0] = fp->max_acc * FP_SHAVE[i][0];
        in.max_jerk[0] = fp->max_jerk * FP_SHAVE[i][1];
        r = j->rk.update(in, j->out);
        if (r == ruckig::Result::Working || r == ruckig::Result::Finished) {
            j->shave = i;
            break;
        }
        /* a failed calculation leaves a spoilt trajectory behind that
           ruckig would go on sampling for an unchanged input */
        j->rk.reset();
    }
    if (r != ruckig::Result::Working && r != ruckig::Result::Finished)
        return false;

    double p = j->out.new_position[0];
    double v = j->out.new_velocity[0];
    double a = j->out.new_acceleration[0];
    if (!std::isfinite(p) || !std::isfinite(v) || !std::isfinite(a)
        || !plausible(fp, p, v, a, j->rk.delta_time)) {
        j->rk.reset();          /* do not keep sampling a bad trajectory */
        return false;
    }
    if (r == ruckig::Result::Finished) {
        /* the trajectory is over: on the goal exactly */
        if (!stop)
            p = goal;
        v = stop ? vgoal : 0.0;
        a = 0.0;
    }
    fp->pos = p;
    fp->vel = v;
    fp->acc = a;
    return true;
}

} // namespace

extern "C" {

void *fp_jerk_new(void);
void fp_jerk_delete(void *impl);
void fp_jerk_reset(void *impl);
int fp_jerk_update(freeplan_t *fp, double dt, int velocity_mode,
                   double vel_goal);

void *fp_jerk_new(void)
{
    return new (std::nothrow) jerk_state();
}

void fp_jerk_delete(void *impl)
{
    delete static_cast<jerk_state *>(impl);
}

void fp_jerk_reset(void *impl)
{
    jerk_state *j = static_cast<jerk_state *>(impl);

    j->rk.reset();
    j->sub_valid = false;
    j->shave = 0;
}

/* one cycle of FP_JERK: toward fp->target, or with velocity_mode toward
   the velocity vel_goal (zero: a stop).  Returns 0, or -1 when ruckig
   could not even compute a stop (the caller then brakes by itself). */
int fp_jerk_update(freeplan_t *fp, double dt, int velocity_mode,
                   double vel_goal)
{
    jerk_state *j = static_cast<jerk_state *>(fp->impl);
    double goal = fp->target;

    j->rk.delta_time = dt;
    if (!velocity_mode) {
        double d = goal - fp->pos;
        double reach = fp->max_vel * FP_SUB_SECONDS;
        double brake = 4.0 * fp->max_vel * fp->max_vel / fp->max_acc;

        if (reach < brake)          /* keep the advance clear of braking */
            reach = brake;

        if (reach > 0.0 && std::fabs(d) > reach) {
            /* a long move: aim at a point reach ahead, moved on when
               half of it is covered (so ruckig recomputes rarely) */
            double ahead = j->sub - fp->pos;
            if (!j->sub_valid || ahead * d <= 0.0
                || std::fabs(ahead) < 0.5 * reach
                || std::fabs(ahead) > std::fabs(d))
                j->sub = fp->pos + (d > 0.0 ? reach : -reach);
            j->sub_valid = true;
            goal = j->sub;
        } else {
            j->sub_valid = false;
        }
        if (jerk_step(j, fp, goal, false, 0.0)) {
            fp->active = !(fp->vel == 0.0 && fp->acc == 0.0
                           && fp->pos == fp->target);
            return 0;
        }
        /* no trajectory to the target: stop instead (and try again
           next cycle) */
        vel_goal = 0.0;
    }
    if (jerk_step(j, fp, goal, true, vel_goal)) {
        fp->active = !velocity_mode || !(fp->vel == 0.0 && fp->acc == 0.0);
        return 0;
    }
    return -1;
}

} // extern "C"
