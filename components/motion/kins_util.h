/*
 * kins_util.h - helpers shared by the kinematics modules of halsdk
 * (trivkins, corexykins, scarakins, lineardeltakins).  The helpers meant
 * for any kinematics author are declared in kinematics.h; this header
 * adds small ones that only these modules use.
 */
#ifndef HALSDK_KINS_UTIL_H
#define HALSDK_KINS_UTIL_H

#include "kinematics.h"

#define KINS_PI 3.14159265358979323846
#define KINS_TO_RAD (KINS_PI / 180.0)
#define KINS_TO_DEG (180.0 / KINS_PI)

/* name used in messages of kins_util.c (default: the module's name) */
extern void kins_set_name(const char *name);
extern const char *kins_name(void);

/* 1 when the n values are all finite numbers */
extern int kins_all_finite(const double *v, int n);
/* 1 when the nine axes of a pose are all finite */
extern int kins_pose_finite(const EmcPose *p);

/* kinstype= of trivkins: "1"/"identity", "b"/"both", "f"/"forward",
   "i"/"inverse" (any case) -> KINEMATICS_*; -1 for anything else */
extern int kins_parse_type(const char *s);

/* kins_module.c (linked into the modules of halsdk): the module's
   component, made and made ready by kins_component_ready(), removed at
   unload */
extern int kins_comp_id;
extern int kins_component_ready(const char *name);

#endif
