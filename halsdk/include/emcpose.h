/*
 * emcpose.h - Cartesian positions of the motion controller.
 *
 * The type and member names are those that kinematics code written for
 * LinuxCNC uses (pose->tran.x, pose->a ...), so such code compiles
 * unchanged.
 */
#ifndef HALSDK_EMCPOSE_H
#define HALSDK_EMCPOSE_H

typedef struct PmCartesian {
    double x, y, z;
} PmCartesian;

/* a position in the nine axes X Y Z A B C U V W */
typedef struct EmcPose {
    PmCartesian tran;
    double a, b, c;
    double u, v, w;
} EmcPose;

/* axis number (0 = X ... 8 = W) <-> member of a pose */
static inline double *emcpose_axis(EmcPose *p, int axis)
{
    switch (axis) {
    case 0: return &p->tran.x;
    case 1: return &p->tran.y;
    case 2: return &p->tran.z;
    case 3: return &p->a;
    case 4: return &p->b;
    case 5: return &p->c;
    case 6: return &p->u;
    case 7: return &p->v;
    default: return &p->w;
    }
}

#endif
