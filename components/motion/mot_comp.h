/*
 * mot_comp.h - per-joint backlash and lead-screw compensation of the
 * motion controller (realtime, no allocation: the table lives in the
 * struct).
 *
 * Every servo cycle motmod calls mot_comp_update() with the joint's
 * commanded position and velocity.  The raw correction (backlash_corr)
 * depends on the direction of the commanded motion, which is the sign of
 * the last non-zero commanded velocity:
 *   - with a screw table (entries > 0): the forward trim when moving
 *     positive, the reverse trim when moving negative, interpolated
 *     linearly between the table's nominal positions and held at the end
 *     values outside the table.  The backlash value is not used then (the
 *     table's trims hold the lost motion, as the reference's manual says
 *     of COMP_FILE and BACKLASH);
 *   - without a table: +backlash/2 moving positive, -backlash/2 moving
 *     negative.
 * Before the first motion the direction is unknown and the correction is
 * the mean of both (0 for backlash alone).
 *
 * The applied correction (backlash_filt) follows the raw one with a
 * trapezoidal profile (the free planner's, freeplan.h) limited to
 * MOT_COMP_VEL_SHARE of the joint's velocity limit and MOT_COMP_ACC_SHARE
 * of its acceleration limit; backlash_vel is its velocity.  So
 * motor_pos_cmd = pos_cmd + backlash_filt + offset moves at most 1.5
 * times the joint's limits while a reversal is taken up (the reference's
 * manual advises giving the drive 1.5 to 2 times MAX_ACCELERATION when
 * backlash is compensated).  With no usable limits (<= 0, NaN) the
 * correction is applied at once.
 */
#ifndef HALSDK_MOT_COMP_H
#define HALSDK_MOT_COMP_H

#include "freeplan.h"

#define MOT_COMP_SIZE 256           /* entries of a screw table */
#define MOT_COMP_VEL_SHARE 0.5      /* of the joint's velocity limit */
#define MOT_COMP_ACC_SHARE 0.5      /* of the joint's acceleration limit */

typedef struct {
    double nominal;                 /* commanded position */
    double fwd_trim;                /* correction moving positive */
    double rev_trim;                /* correction moving negative */
} mot_comp_entry_t;

typedef struct {
    int entries;                    /* used entries of table */
    mot_comp_entry_t table[MOT_COMP_SIZE];  /* nominal strictly increasing */
    double backlash;                /* >= 0; used without a table */
    int dir;                        /* +1, -1; 0 before the first motion */
    double corr;                    /* raw correction (backlash_corr) */
    freeplan_t filt;                /* applied correction: pos, vel */
} mot_comp_t;

/* empty table, no backlash, correction 0 (load time or any time) */
void mot_comp_init(mot_comp_t *c);

/* empty the table (backlash, direction and correction stay) */
void mot_comp_clear(mot_comp_t *c);

/* append an entry; 0, or -EINVAL with the reason in why[len] (why may be
   NULL) when nominal or a trim is not finite, nominal is not greater
   than the previous entry's, or the table is full */
int mot_comp_add(mot_comp_t *c, double nominal, double fwd_trim,
                 double rev_trim, char *why, int len);

/* set the backlash; 0, or -EINVAL (negative or not finite) with why */
int mot_comp_set_backlash(mot_comp_t *c, double backlash, char *why,
                          int len);

/* the table's trim at pos for direction dir (+1 forward, -1 reverse, 0
   the mean of both); 0 with an empty table */
double mot_comp_lookup(const mot_comp_t *c, double pos, int dir);

/* one servo cycle of dt seconds: pos_cmd and vel_cmd of the joint,
   max_vel and max_acc its limits (the correction uses a share of them,
   see above); writes the raw correction (backlash_corr), the applied
   one (backlash_filt) and its velocity (backlash_vel).  A NaN pos_cmd
   keeps the previous correction. */
void mot_comp_update(mot_comp_t *c, double pos_cmd, double vel_cmd,
                     double dt, double max_vel, double max_acc,
                     double *corr, double *filt, double *filt_vel);

#endif
