/*
 * lineardeltakins.c - kinematics of a linear delta robot (Rostock,
 * Kossel): three vertical towers at 120 degrees, each with a carriage
 * (joints 0..2, carriage height) holding a rod of length L to the
 * effector.
 *
 *   loadrt lineardeltakins
 *
 * Tower 0 is at (0, R), tower 1 at (-R cos 30, -R/2) and tower 2 at
 * (R cos 30, -R/2): 120 degrees apart, going from +Y towards -X first.
 * (0, 0) is the centre of the work volume.  The
 * effector hangs below the carriages: carriage i is at
 *   j[i] = z + sqrt(L^2 - (x - xi)^2 - (y - yi)^2).
 * Joints 3..8 pass to A B C U V W unchanged (e.g. an extruder on A).
 * R and L are input pins and may change at any time; a change moves the
 * joints for the same world position.
 */
#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_errno.h"
#include "hal.h"
#include "kins_util.h"

#include <math.h>

MODULE_LICENSE("GPL");
MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("Linear delta robot kinematics");

typedef struct {
    hal_float_t *r;             /* effective radius of the towers */
    hal_float_t *l;             /* rod length */
} delta_pins_t;

static delta_pins_t *pins;
/* x and y of the three towers for radius r */
static void towers(double r, double tx[3], double ty[3])
{
    const double s = 0.86602540378443864676;   /* sin 60 = cos 30 */

    tx[0] = 0.0;
    ty[0] = r;
    tx[1] = -r * s;
    ty[1] = -0.5 * r;
    tx[2] = r * s;
    ty[2] = -0.5 * r;
}

int kinematicsInverse(const EmcPose *world, double *joint,
                      const KINEMATICS_INVERSE_FLAGS *iflags,
                      KINEMATICS_FORWARD_FLAGS *fflags)
{
    double r = *pins->r, l = *pins->l;
    double tx[3], ty[3], h[3], dx, dy;
    int n;

    (void)iflags;
    if (!kins_pose_finite(world) || !isfinite(r) || !isfinite(l)
        || r <= 0.0 || l <= 0.0)
        return -1;
    towers(r, tx, ty);
    for (n = 0; n < 3; n++) {
        dx = world->tran.x - tx[n];
        dy = world->tran.y - ty[n];
        h[n] = l * l - dx * dx - dy * dy;
        if (h[n] < 0.0)
            return -1;          /* the rod cannot reach that far */
    }
    for (n = 0; n < 3; n++)
        joint[n] = world->tran.z + sqrt(h[n]);
    joint[3] = world->a;
    joint[4] = world->b;
    joint[5] = world->c;
    joint[6] = world->u;
    joint[7] = world->v;
    joint[8] = world->w;
    *fflags = 0;
    return 0;
}

/*
 * The effector is where three spheres of radius L around the carriages
 * meet.  The differences of the sphere equations are two planes, which
 * give x and y as linear functions of z; sphere 0 then gives a quadratic
 * in z whose lower root is the effector (it hangs below the carriages).
 */
int kinematicsForward(const double *joint, EmcPose *world,
                      const KINEMATICS_FORWARD_FLAGS *fflags,
                      KINEMATICS_INVERSE_FLAGS *iflags)
{
    double r = *pins->r, l = *pins->l;
    double tx[3], ty[3], k[3];
    double a11, a12, a21, a22, det, b1, b2, c1, c2;
    double ax, bx, ay, by, ex, ey, qa, qb, qc, disc, q, z1, z2, z;
    int n;

    (void)fflags;
    (void)iflags;
    if (!kins_all_finite(joint, 9) || !isfinite(r) || !isfinite(l)
        || r <= 0.0 || l <= 0.0)
        return -1;
    towers(r, tx, ty);
    for (n = 0; n < 3; n++)
        k[n] = tx[n] * tx[n] + ty[n] * ty[n] + joint[n] * joint[n];
    /* sphere n - sphere 0:
       2(xn-x0) x + 2(yn-y0) y = kn - k0 - 2(jn-j0) z */
    a11 = 2.0 * (tx[1] - tx[0]);
    a12 = 2.0 * (ty[1] - ty[0]);
    a21 = 2.0 * (tx[2] - tx[0]);
    a22 = 2.0 * (ty[2] - ty[0]);
    b1 = k[1] - k[0];
    b2 = k[2] - k[0];
    c1 = -2.0 * (joint[1] - joint[0]);
    c2 = -2.0 * (joint[2] - joint[0]);
    det = a11 * a22 - a12 * a21;
    /* x = ax z + bx, y = ay z + by (Cramer's rule) */
    ax = (c1 * a22 - a12 * c2) / det;
    bx = (b1 * a22 - a12 * b2) / det;
    ay = (a11 * c2 - c1 * a21) / det;
    by = (a11 * b2 - b1 * a21) / det;
    /* sphere 0: (x - x0)^2 + (y - y0)^2 + (z - j0)^2 = L^2 */
    ex = bx - tx[0];
    ey = by - ty[0];
    qa = ax * ax + ay * ay + 1.0;
    qb = 2.0 * (ax * ex + ay * ey - joint[0]);
    qc = ex * ex + ey * ey + joint[0] * joint[0] - l * l;
    disc = qb * qb - 4.0 * qa * qc;
    if (disc < 0.0)
        return -1;              /* carriages too far apart for the rods */
    /* both roots without cancellation; keep the lower one */
    q = -0.5 * (qb + (qb < 0.0 ? -sqrt(disc) : sqrt(disc)));
    if (q == 0.0)
        return -1;
    z1 = q / qa;
    z2 = qc / q;
    z = z1 < z2 ? z1 : z2;
    world->tran.x = ax * z + bx;
    world->tran.y = ay * z + by;
    world->tran.z = z;
    world->a = joint[3];
    world->b = joint[4];
    world->c = joint[5];
    world->u = joint[6];
    world->v = joint[7];
    world->w = joint[8];
    return 0;
}

KINEMATICS_TYPE kinematicsType(void)
{
    return KINEMATICS_BOTH;
}

KINS_NOT_SWITCHABLE

int rtapi_app_main(void)
{
    int r;

    kins_comp_id = hal_init("lineardeltakins");
    if (kins_comp_id < 0)
        return kins_comp_id;
    pins = hal_malloc(sizeof(*pins));
    if (!pins) {
        rtapi_print_msg(RTAPI_MSG_ERR, "lineardeltakins: out of HAL memory\n");
        hal_exit(kins_comp_id);
        return -ENOMEM;
    }
    r = hal_pin_float_newf(HAL_IN, &pins->r, kins_comp_id,
                           "lineardeltakins.R");
    if (!r)
        r = hal_pin_float_newf(HAL_IN, &pins->l, kins_comp_id,
                               "lineardeltakins.L");
    if (r) {
        hal_exit(kins_comp_id);
        return r;
    }
    /* a mid-size Kossel */
    *pins->r = 130.25;
    *pins->l = 269.0;
    hal_ready(kins_comp_id);
    return 0;
}
