/*
 * scarakins.c - kinematics of a SCARA robot, switchable to identity.
 *
 *   loadrt scarakins [coordinates=LETTERS] [sparm=STRING]
 *
 * Joints: 0 inner arm angle (degrees, around the base axis), 1 outer arm
 * angle relative to the inner arm (degrees), 2 quill travel (down is
 * positive), 3 tool rotation relative to the outer arm (degrees), 4 and
 * 5 pass to A and B.  World C is the tool's heading, j0 + j1 + j3.
 *
 * Geometry (pins, machine units; see the D1..D6 pins below):
 *   x = D2 cos(j0) + D4 cos(j0 + j1) + D6 cos(c)
 *   y = D2 sin(j0) + D4 sin(j0 + j1) + D6 sin(c)
 *   z = D1 + D3 - D5 - j2
 *
 * Two joint sets reach most points (elbow on either side).  The inverse
 * flags pick one: bit 0 clear gives j1 >= 0, set gives j1 < 0; the
 * forward transform sets that bit from the sign of j1 so that a round
 * trip keeps the elbow where it was.
 *
 * Switchable (motion.switchkins-type): type 0 is the SCARA transform,
 * type 1 identity over coordinates= (default xyzabc, no duplicates),
 * type 2 a user slot that here is identity too and counts its calls in
 * userk.fct / userk.ict.  sparm= is accepted and not used.
 */
#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_errno.h"
#include "hal.h"
#include "kins_util.h"

#include <math.h>

MODULE_LICENSE("GPL");
MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("SCARA kinematics, switchable to identity");

static char *coordinates = "xyzabc";
RTAPI_MP_STRING(coordinates, "Axis letters of the identity type (type 1)");
static char *sparm = "";
RTAPI_MP_STRING(sparm, "Module string parameter (accepted, not used)");

typedef struct {
    hal_float_t *d[6];          /* D1..D6 */
    hal_bit_t *is[3];           /* kinstype.is-N */
    hal_s32_t *fct, *ict;       /* calls of the user type */
} scara_pins_t;

static scara_pins_t *pins;
static int sel;                 /* selected type: 0 scara, 1, 2 identity */

/* a reach test at full stretch must not fail on the last bit */
#define REACH_TOL 1e-9

static int scara_forward(const double *j, EmcPose *w,
                         KINEMATICS_INVERSE_FLAGS *iflags)
{
    double d1 = *pins->d[0], d2 = *pins->d[1], d3 = *pins->d[2];
    double d4 = *pins->d[3], d5 = *pins->d[4], d6 = *pins->d[5];
    double a0, a1, c;

    if (!kins_all_finite(j, 6))
        return -1;
    a0 = j[0] * KINS_TO_RAD;
    a1 = (j[0] + j[1]) * KINS_TO_RAD;
    c = j[0] + j[1] + j[3];
    w->tran.x = d2 * cos(a0) + d4 * cos(a1) + d6 * cos(c * KINS_TO_RAD);
    w->tran.y = d2 * sin(a0) + d4 * sin(a1) + d6 * sin(c * KINS_TO_RAD);
    w->tran.z = d1 + d3 - d5 - j[2];
    w->a = j[4];
    w->b = j[5];
    w->c = c;
    w->u = w->v = w->w = 0.0;
    *iflags = j[1] < 0.0 ? 1 : 0;
    return 0;
}

static int scara_inverse(const EmcPose *w, double *j,
                         const KINEMATICS_INVERSE_FLAGS *iflags)
{
    double d1 = *pins->d[0], d2 = *pins->d[1], d3 = *pins->d[2];
    double d4 = *pins->d[3], d5 = *pins->d[4], d6 = *pins->d[5];
    double cr, xe, ye, cq1, q0, q1, j0;

    if (!kins_pose_finite(w) || !isfinite(d1 + d2 + d3 + d4 + d5 + d6))
        return -1;
    if (d2 <= 0.0 || d4 <= 0.0)
        return -1;              /* no arm, no solution */
    /* the wrist centre: the tool tip minus its offset along heading c */
    cr = w->c * KINS_TO_RAD;
    xe = w->tran.x - d6 * cos(cr);
    ye = w->tran.y - d6 * sin(cr);
    /* law of cosines for the elbow angle */
    cq1 = (xe * xe + ye * ye - d2 * d2 - d4 * d4) / (2.0 * d2 * d4);
    if (cq1 > 1.0 + REACH_TOL || cq1 < -1.0 - REACH_TOL)
        return -1;              /* out of reach */
    if (cq1 > 1.0)
        cq1 = 1.0;
    if (cq1 < -1.0)
        cq1 = -1.0;
    q1 = acos(cq1);
    if (iflags && (*iflags & 1))
        q1 = -q1;
    q0 = atan2(ye, xe) - atan2(d4 * sin(q1), d2 + d4 * cos(q1));
    j0 = q0 * KINS_TO_DEG;
    /* inner arm angle in (-180, 180] */
    while (j0 > 180.0)
        j0 -= 360.0;
    while (j0 <= -180.0)
        j0 += 360.0;
    j[0] = j0;
    j[1] = q1 * KINS_TO_DEG;
    j[2] = d1 + d3 - d5 - w->tran.z;
    j[3] = w->c - j[0] - j[1];
    j[4] = w->a;
    j[5] = w->b;
    return 0;
}

int kinematicsForward(const double *joint, EmcPose *world,
                      const KINEMATICS_FORWARD_FLAGS *fflags,
                      KINEMATICS_INVERSE_FLAGS *iflags)
{
    switch (sel) {
    case 0:
        return scara_forward(joint, world, iflags);
    case 2:
        *pins->fct += 1;
        /* fall through */
    default:
        return identityKinematicsForward(joint, world, fflags, iflags);
    }
}

int kinematicsInverse(const EmcPose *world, double *joint,
                      const KINEMATICS_INVERSE_FLAGS *iflags,
                      KINEMATICS_FORWARD_FLAGS *fflags)
{
    switch (sel) {
    case 0:
        if (scara_inverse(world, joint, iflags))
            return -1;
        *fflags = 0;
        return 0;
    case 2:
        *pins->ict += 1;
        /* fall through */
    default:
        return identityKinematicsInverse(world, joint, iflags, fflags);
    }
}

KINEMATICS_TYPE kinematicsType(void)
{
    return KINEMATICS_BOTH;
}

int kinematicsSwitchable(void)
{
    return 1;
}

int kinematicsSwitch(int switchkins_type)
{
    int n;

    if (switchkins_type < 0 || switchkins_type > 2) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "scarakins: kinematics type %d does not exist "
                        "(0 scara, 1 identity, 2 user)\n", switchkins_type);
        return -1;
    }
    sel = switchkins_type;
    for (n = 0; n < 3; n++)
        *pins->is[n] = n == sel;
    return 0;
}

EXPORT_SYMBOL(kinematicsSwitchable);
EXPORT_SYMBOL(kinematicsSwitch);

int rtapi_app_main(void)
{
    /* defaults of D1..D6: a small SCARA arm */
    static const double dflt[6] = { 490.0, 340.0, 50.0, 250.0, 50.0, 50.0 };
    kparms kp = {
        .sparm = sparm,
        .kinsname = "scarakins",
        .halprefix = "scarakins",
        .required_coordinates = "xyzabc",
        .max_joints = 6,
        .allow_duplicates = 0,
    };
    int n, r;

    if (!coordinates || !coordinates[0]) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "scarakins: coordinates= is empty: give one axis "
                        "letter (XYZABCUVW) per joint\n");
        return -EINVAL;
    }
    if (identityKinematicsSetup(0, coordinates, &kp))
        return -EINVAL;
    kins_comp_id = hal_init("scarakins");
    if (kins_comp_id < 0)
        return kins_comp_id;
    pins = hal_malloc(sizeof(*pins));
    if (!pins) {
        rtapi_print_msg(RTAPI_MSG_ERR, "scarakins: out of HAL memory\n");
        hal_exit(kins_comp_id);
        return -ENOMEM;
    }
    for (n = 0; n < 6; n++) {
        r = hal_pin_float_newf(HAL_IN, &pins->d[n], kins_comp_id,
                               "scarakins.D%d", n + 1);
        if (r)
            goto fail;
        *pins->d[n] = dflt[n];
    }
    for (n = 0; n < 3; n++) {
        r = hal_pin_bit_newf(HAL_OUT, &pins->is[n], kins_comp_id,
                             "kinstype.is-%d", n);
        if (r)
            goto fail;
        *pins->is[n] = n == 0;
    }
    r = hal_pin_s32_newf(HAL_IO, &pins->fct, kins_comp_id, "userk.fct");
    if (!r)
        r = hal_pin_s32_newf(HAL_IO, &pins->ict, kins_comp_id, "userk.ict");
    if (r)
        goto fail;
    sel = 0;
    hal_ready(kins_comp_id);
    return 0;

fail:
    hal_exit(kins_comp_id);
    return r;
}
