/*
 * trivkins.c - trivial kinematics: each joint is one axis.
 *
 *   loadrt trivkins [coordinates=LETTERS] [kinstype=1|b|f|i]
 *
 * coordinates= gives one axis letter per joint, in joint order (default
 * xyzabcuvw; either case).  A letter may repeat: all its joints follow
 * the axis (a gantry) and the axis reads the first of them.  kinstype=
 * sets what kinematicsType() reports: 1 identity (default), b both,
 * f forward only, i inverse only.
 */
#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_errno.h"
#include "hal.h"
#include "kins_util.h"

MODULE_LICENSE("GPL");
MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("Trivial kinematics: joints are axes, by letter");

static char *coordinates = "xyzabcuvw";
RTAPI_MP_STRING(coordinates, "Axis letter of each joint, in joint order");
static char *kinstype = "1";
RTAPI_MP_STRING(kinstype, "Kinematics type: 1 identity, b both, "
                "f forward only, i inverse only");

static KINEMATICS_TYPE ktype = KINEMATICS_IDENTITY;

int kinematicsForward(const double *joint, EmcPose *world,
                      const KINEMATICS_FORWARD_FLAGS *fflags,
                      KINEMATICS_INVERSE_FLAGS *iflags)
{
    return identityKinematicsForward(joint, world, fflags, iflags);
}

int kinematicsInverse(const EmcPose *world, double *joint,
                      const KINEMATICS_INVERSE_FLAGS *iflags,
                      KINEMATICS_FORWARD_FLAGS *fflags)
{
    return identityKinematicsInverse(world, joint, iflags, fflags);
}

KINEMATICS_TYPE kinematicsType(void)
{
    return ktype;
}

KINS_NOT_SWITCHABLE

int rtapi_app_main(void)
{
    kparms kp = {
        .kinsname = "trivkins",
        .max_joints = KINS_MAX_JOINTS,
        .allow_duplicates = 1,
    };
    int t, n, k, dup = 0;

    t = kins_parse_type(kinstype);
    if (t < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "trivkins: kinstype=%s is not a kinematics type; use "
                        "1 (identity), b (both), f (forward only) or "
                        "i (inverse only)\n", kinstype);
        return -EINVAL;
    }
    ktype = (KINEMATICS_TYPE)t;
    if (!coordinates || !coordinates[0]) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "trivkins: coordinates= is empty: give one axis "
                        "letter (XYZABCUVW) per joint\n");
        return -EINVAL;
    }
    if (identityKinematicsSetup(0, coordinates, &kp))
        return -EINVAL;
    /* a duplicated letter with identity type: joints of the axis can
       only be jogged together before homing; say how to change that */
    for (n = 0; coordinates[n]; n++)
        for (k = n + 1; coordinates[k]; k++)
            if ((coordinates[n] | 0x20) == (coordinates[k] | 0x20))
                dup = 1;
    if (dup && ktype != KINEMATICS_BOTH)
        rtapi_print_msg(RTAPI_MSG_INFO,
                        "trivkins: coordinates=%s repeats a letter; "
                        "kinstype=both lets each of its joints be jogged "
                        "alone\n", coordinates);
    return kins_component_ready("trivkins");
}
