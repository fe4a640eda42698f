/*
 * kins_util.c - joint <-> axis letter mapping and identity kinematics
 * for kinematics modules (see kinematics.h for the interface).
 *
 * Each module links its own copy of this file, so the current mapping
 * below belongs to the module that uses it.  Only the setup functions
 * print or fail; the transforms are plain loops, safe in realtime.
 */
#include "rtapi.h"
#include "rtapi_app.h"
#include "hal.h"
#include "kins_util.h"

#include <math.h>
#include <string.h>
#include <strings.h>

#define STR_(x) #x
#define STR(x) STR_(x)
#ifdef HALSDK_MODULE_NAME
#define DEFAULT_NAME STR(HALSDK_MODULE_NAME)
#else
#define DEFAULT_NAME "kinematics"
#endif

static const char *name = DEFAULT_NAME;

/* current mapping: axis number of each joint, -1 when unnamed */
static int axis_of[KINS_MAX_JOINTS];
static int njoints;

void kins_set_name(const char *n)
{
    if (n && n[0])
        name = n;
}

const char *kins_name(void)
{
    return name;
}

int kins_mapped_joints(void)
{
    return njoints;
}

int kins_all_finite(const double *v, int n)
{
    int i;

    for (i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

int kins_pose_finite(const EmcPose *p)
{
    return isfinite(p->tran.x) && isfinite(p->tran.y) && isfinite(p->tran.z)
        && isfinite(p->a) && isfinite(p->b) && isfinite(p->c)
        && isfinite(p->u) && isfinite(p->v) && isfinite(p->w);
}

int kins_parse_type(const char *s)
{
    if (!s || !s[0])
        return KINEMATICS_IDENTITY;
    if (!strcmp(s, "1") || !strcasecmp(s, "identity"))
        return KINEMATICS_IDENTITY;
    if (!strcasecmp(s, "b") || !strcasecmp(s, "both"))
        return KINEMATICS_BOTH;
    if (!strcasecmp(s, "f") || !strcasecmp(s, "forward"))
        return KINEMATICS_FORWARD_ONLY;
    if (!strcasecmp(s, "i") || !strcasecmp(s, "inverse"))
        return KINEMATICS_INVERSE_ONLY;
    return -1;
}

/* axis number of a letter (either case), -1 if it is not an axis */
static int axis_number(char c)
{
    const char *letters = KINS_AXIS_LETTERS;
    const char *p;

    if (c >= 'a' && c <= 'z')
        c = c - 'a' + 'A';
    p = c ? strchr(letters, c) : NULL;
    return p ? (int)(p - letters) : -1;
}

int map_coordinates_to_jnumbers(const char *coordinates,
                                const int max_joints,
                                const int allow_duplicates,
                                int axis_idx_for_jno[])
{
    int n, len, axis, seen = 0;

    if (!coordinates || !coordinates[0]) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "%s: coordinates= is empty: give one axis letter "
                        "(XYZABCUVW) per joint\n", name);
        return -1;
    }
    len = strlen(coordinates);
    if (max_joints < 1 || max_joints > KINS_MAX_JOINTS) {
        rtapi_print_msg(RTAPI_MSG_ERR, "%s: bad max_joints %d (1..%d)\n",
                        name, max_joints, KINS_MAX_JOINTS);
        return -1;
    }
    if (len > max_joints) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "%s: coordinates=%s names %d joints, at most %d "
                        "are allowed\n", name, coordinates, len, max_joints);
        return -1;
    }
    for (n = 0; n < len; n++) {
        axis = axis_number(coordinates[n]);
        if (axis < 0) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "%s: coordinates=%s: '%c' (joint %d) is not an "
                            "axis letter; use letters of XYZABCUVW\n",
                            name, coordinates, coordinates[n], n);
            return -1;
        }
        if ((seen & (1 << axis)) && !allow_duplicates) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "%s: coordinates=%s: letter %c is given twice, "
                            "which this kinematics does not allow\n",
                            name, coordinates, KINS_AXIS_LETTERS[axis]);
            return -1;
        }
        seen |= 1 << axis;
    }
    /* all good: fill the caller's table and the current mapping */
    for (n = 0; n < max_joints; n++)
        axis_idx_for_jno[n] = n < len ? axis_number(coordinates[n]) : -1;
    for (n = 0; n < KINS_MAX_JOINTS; n++)
        axis_of[n] = n < len ? axis_number(coordinates[n]) : -1;
    njoints = len;
    return 0;
}

int mapped_joints_to_position(const int max_joints, const double *joints,
                              EmcPose *pose)
{
    int n, axis, done = 0;
    int last = max_joints < njoints ? max_joints : njoints;

    for (axis = 0; axis < 9; axis++)
        *emcpose_axis(pose, axis) = 0.0;
    for (n = 0; n < last; n++) {
        axis = axis_of[n];
        /* a gantry axis follows the first of its joints */
        if (axis >= 0 && !(done & (1 << axis))) {
            *emcpose_axis(pose, axis) = joints[n];
            done |= 1 << axis;
        }
    }
    return 0;
}

int position_to_mapped_joints(const int max_joints, const EmcPose *pos,
                              double *joints)
{
    int n;
    int last = max_joints < njoints ? max_joints : njoints;

    for (n = 0; n < last; n++)
        if (axis_of[n] >= 0)
            joints[n] = *emcpose_axis((EmcPose *)pos, axis_of[n]);
    return 0;
}

int identityKinematicsSetup(const int comp_id, const char *coordinates,
                            kparms *ksetup_parms)
{
    int map[KINS_MAX_JOINTS];
    char dflt[10];
    int max = ksetup_parms ? ksetup_parms->max_joints : 9;
    int dups = ksetup_parms ? ksetup_parms->allow_duplicates : 1;
    int n;

    (void)comp_id;
    if (ksetup_parms)
        kins_set_name(ksetup_parms->kinsname);
    if (max < 1 || max > KINS_MAX_JOINTS)
        max = KINS_MAX_JOINTS;
    if (!coordinates || !coordinates[0]) {
        /* one joint per axis letter in order, as many as allowed */
        n = max < 9 ? max : 9;
        memcpy(dflt, KINS_AXIS_LETTERS, n);
        dflt[n] = 0;
        coordinates = dflt;
    }
    if (map_coordinates_to_jnumbers(coordinates, max, dups, map))
        return -1;
    for (n = 0; n < njoints; n++)
        rtapi_print_msg(RTAPI_MSG_INFO, "%s: joint %d is axis %c\n", name, n,
                        KINS_AXIS_LETTERS[map[n]]);
    return 0;
}

int identityKinematicsForward(const double *joint, EmcPose *world,
                              const KINEMATICS_FORWARD_FLAGS *fflags,
                              KINEMATICS_INVERSE_FLAGS *iflags)
{
    (void)fflags;
    (void)iflags;
    return mapped_joints_to_position(KINS_MAX_JOINTS, joint, world);
}

int identityKinematicsInverse(const EmcPose *world, double *joint,
                              const KINEMATICS_INVERSE_FLAGS *iflags,
                              KINEMATICS_FORWARD_FLAGS *fflags)
{
    (void)iflags;
    (void)fflags;
    return position_to_mapped_joints(KINS_MAX_JOINTS, world, joint);
}
