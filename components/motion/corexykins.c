/*
 * corexykins.c - kinematics of a CoreXY machine.
 *
 *   loadrt corexykins
 *
 * Two motors (joints 0 and 1) drive the X Y carriage through crossed
 * belts: X moves by the half sum of the two, Y by their half difference.
 * Joint 2 is Z and joints 3..8 are A B C U V W, unchanged.
 */
#include "rtapi.h"
#include "rtapi_app.h"
#include "hal.h"
#include "kins_util.h"

MODULE_LICENSE("GPL");
MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("CoreXY kinematics");

int kinematicsForward(const double *joint, EmcPose *world,
                      const KINEMATICS_FORWARD_FLAGS *fflags,
                      KINEMATICS_INVERSE_FLAGS *iflags)
{
    (void)fflags;
    (void)iflags;
    world->tran.x = 0.5 * (joint[0] + joint[1]);
    world->tran.y = 0.5 * (joint[0] - joint[1]);
    world->tran.z = joint[2];
    world->a = joint[3];
    world->b = joint[4];
    world->c = joint[5];
    world->u = joint[6];
    world->v = joint[7];
    world->w = joint[8];
    return 0;
}

int kinematicsInverse(const EmcPose *world, double *joint,
                      const KINEMATICS_INVERSE_FLAGS *iflags,
                      KINEMATICS_FORWARD_FLAGS *fflags)
{
    (void)iflags;
    (void)fflags;
    joint[0] = world->tran.x + world->tran.y;
    joint[1] = world->tran.x - world->tran.y;
    joint[2] = world->tran.z;
    joint[3] = world->a;
    joint[4] = world->b;
    joint[5] = world->c;
    joint[6] = world->u;
    joint[7] = world->v;
    joint[8] = world->w;
    return 0;
}

KINEMATICS_TYPE kinematicsType(void)
{
    return KINEMATICS_BOTH;
}

KINS_NOT_SWITCHABLE

int rtapi_app_main(void)
{
    return kins_component_ready("corexykins");
}
