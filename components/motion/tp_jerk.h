/*
 * tp_jerk.h - jerk-limited steps of tpmod's path parameter (tp_jerk.cpp,
 * ruckig).
 */
#ifndef HALSDK_TP_JERK_H
#define HALSDK_TP_JERK_H

#ifdef __cplusplus
extern "C" {
#endif

/* One cycle (dt) of the time-optimal jerk-limited profile of the path
   parameter from here (0) with velocity v0 and acceleration a0: toward
   the velocity vf (position == 0), or to the point dist ahead reached at
   velocity vf with zero acceleration (position != 0), under vmax, amax
   and jmax.  Writes the distance p covered in the cycle, the velocity v
   and acceleration a at its end; returns 0, or -1 when no profile was
   found (the caller falls back). */
int tp_jerk_step(int position, double dist, double vf, double v0,
                 double a0, double vmax, double amax, double jmax,
                 double dt, double *p, double *v, double *a);

#ifdef __cplusplus
}
#endif

#endif
