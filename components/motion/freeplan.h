/*
 * freeplan.h - the single-coordinate planner of the motion controller.
 *
 * One planner moves one coordinate (a joint in free mode: jogs and homing
 * moves; an axis in teleop mode) toward a target position under velocity,
 * acceleration and, when max_jerk > 0 and the profile is FP_JERK, jerk
 * limits.  The target and limits may change at any cycle; the planner
 * always continues from its current position, velocity and acceleration,
 * so a new target or a lower velocity limit never makes a step.
 *
 * Realtime rules: fp_update() does not allocate, lock or call Python;
 * fp_init() may allocate (it runs at load time) and fp_free() releases.
 */
#ifndef HALSDK_FREEPLAN_H
#define HALSDK_FREEPLAN_H

#ifdef __cplusplus
extern "C" {
#endif

enum fp_profile {
    FP_TRAPEZOID = 0,       /* velocity and acceleration limits only */
    FP_JERK = 1             /* also the jerk limit (ruckig) */
};

typedef struct {
    /* inputs: the user sets these before fp_update() */
    double target;          /* where to go */
    double max_vel;         /* > 0 */
    double max_acc;         /* > 0 */
    double max_jerk;        /* > 0 with FP_JERK */
    int enable;             /* 1: go to target; 0: stop (decelerate to
                               zero velocity within the limits, then
                               stay) */
    int profile;            /* enum fp_profile */

    /* state: written by the planner (set pos with fp_reset()) */
    double pos, vel, acc;
    int active;             /* 1 while moving (not at rest at target or
                               stopped) */

    void *impl;             /* private: the jerk-limited planner */
} freeplan_t;

/* at load time: zero the planner and allocate its private state;
   returns 0 or -ENOMEM */
int fp_init(freeplan_t *fp);
void fp_free(freeplan_t *fp);

/* put the planner at rest at pos (velocity and acceleration zero,
   enable and active cleared, target = pos) */
void fp_reset(freeplan_t *fp, double pos);

/* one cycle of dt seconds: advance pos, vel, acc */
void fp_update(freeplan_t *fp, double dt);

/* distance needed to stop from the present state under the limits
   (signed: in the direction of motion) */
double fp_stopping_distance(const freeplan_t *fp);

#ifdef __cplusplus
}
#endif

#endif
