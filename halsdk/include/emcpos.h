/* emcpos.h - the name LinuxCNC's kinematics.h includes for EmcPose */
#ifndef HALSDK_EMCPOS_H
#define HALSDK_EMCPOS_H
#include "emcpose.h"
#endif
