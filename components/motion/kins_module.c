/*
 * kins_module.c - what the kinematics modules of halsdk (trivkins,
 * corexykins, scarakins, lineardeltakins) have in common, linked into
 * each of them (components/motion/MODULES):
 *
 * - kinematicsHome(): the home pose is the forward kinematics of the
 *   home joints, with cleared flags;
 * - the exports of the four functions motion calls (a module exports
 *   its switchable-kinematics functions itself, or KINS_NOT_SWITCHABLE);
 * - the module's component (kins_comp_id) and its removal at unload.
 *
 * A kinematics module of one's own need not use it: kinematics.h is the
 * whole interface (docs/kinematics.rst).
 */
#include "rtapi.h"
#include "rtapi_app.h"
#include "hal.h"
#include "kins_util.h"

int kins_comp_id = -1;

int kinematicsHome(EmcPose *world, double *joint,
                   KINEMATICS_FORWARD_FLAGS *fflags,
                   KINEMATICS_INVERSE_FLAGS *iflags)
{
    *fflags = 0;
    *iflags = 0;
    return kinematicsForward(joint, world, fflags, iflags);
}

EXPORT_SYMBOL(kinematicsForward);
EXPORT_SYMBOL(kinematicsInverse);
EXPORT_SYMBOL(kinematicsHome);
EXPORT_SYMBOL(kinematicsType);

int kins_component_ready(const char *name)
{
    kins_comp_id = hal_init(name);
    if (kins_comp_id < 0)
        return kins_comp_id;
    hal_ready(kins_comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    if (kins_comp_id >= 0)
        hal_exit(kins_comp_id);
}
