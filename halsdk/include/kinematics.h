/*
 * kinematics.h - the interface between the motion module and a
 * kinematics module.
 *
 * A kinematics module (trivkins, corexykins, ... or one of your own) is a
 * realtime module that defines the functions declared below and offers
 * them to other modules with EXPORT_SYMBOL(name).  motmod looks them up
 * by name when it loads (halsdk_symbol_find) and calls them through the
 * pointer types at the end of this file.
 *
 * Names, types and argument order are those of LinuxCNC 2.9, so that
 * kinematics code written for it compiles against this header.
 *
 * Units: joints in the machine's joint units (linear or degrees), world
 * positions in the machine's axis units (angles of A B C in degrees).
 * Return value of forward/inverse: 0 on success, non-zero when the
 * position has no (or no unique) solution; on failure the output is left
 * as it was, so a caller never reads NaN from a failed call.
 */
#ifndef HALSDK_KINEMATICS_H
#define HALSDK_KINEMATICS_H

#include "emcpose.h"
#include "rtapi_bool.h"
#include "rtapi_app.h"          /* EXPORT_SYMBOL, halsdk_symbol_find */

#ifdef __cplusplus
extern "C" {
#endif

/* most joints a kinematics function reads or writes (as many as motmod
   can have); the joint arrays passed in have at least this size */
#define KINS_MAX_JOINTS 16

/* the nine axis letters, in axis number order (X = 0 ... W = 8) */
#define KINS_AXIS_LETTERS "XYZABCUVW"

typedef enum {
    KINEMATICS_IDENTITY = 1,    /* joint n is axis letter n: fwd == inv */
    KINEMATICS_FORWARD_ONLY,    /* only the forward transform exists */
    KINEMATICS_INVERSE_ONLY,    /* only the inverse transform exists */
    KINEMATICS_BOTH             /* both exist (non-trivial machines) */
} KINEMATICS_TYPE;

/* Flags that pick one of several solutions: the forward flags tell
   kinematicsForward which world pose to choose for a joint set (e.g.
   platform above or below the base); the inverse flags tell
   kinematicsInverse which joint set to choose for a pose (e.g. elbow
   left or right).  Each transform sets the flags of the other one to
   match the position it was given. */
typedef unsigned long int KINEMATICS_FORWARD_FLAGS;
typedef unsigned long int KINEMATICS_INVERSE_FLAGS;

/* joints -> world pose */
extern int kinematicsForward(const double *joint, EmcPose *world,
                             const KINEMATICS_FORWARD_FLAGS *fflags,
                             KINEMATICS_INVERSE_FLAGS *iflags);

/* world pose -> joints */
extern int kinematicsInverse(const EmcPose *world, double *joint,
                             const KINEMATICS_INVERSE_FLAGS *iflags,
                             KINEMATICS_FORWARD_FLAGS *fflags);

/* pose, joints and flags at the home position; the arguments hold the
   configured values on entry and may be used as they are */
extern int kinematicsHome(EmcPose *world, double *joint,
                          KINEMATICS_FORWARD_FLAGS *fflags,
                          KINEMATICS_INVERSE_FLAGS *iflags);

extern KINEMATICS_TYPE kinematicsType(void);

/* switchable kinematics: kinematicsSwitchable() is 1 when the module has
   more than one transform (type 0 its own, 1 usually identity, 2 a user
   one); kinematicsSwitch(n) selects one, 0 on success */
extern int kinematicsSwitchable(void);
extern int kinematicsSwitch(int switchkins_type);

/* for modules with a single transform: defines and exports the two
   switch functions (not switchable, switching is a no-op) */
#define KINS_NOT_SWITCHABLE                                             \
    int kinematicsSwitchable(void) { return 0; }                       \
    int kinematicsSwitch(int switchkins_type)                          \
    {                                                                   \
        (void)switchkins_type;                                          \
        return 0;                                                       \
    }                                                                   \
    EXPORT_SYMBOL(kinematicsSwitchable);                                \
    EXPORT_SYMBOL(kinematicsSwitch);

/*
 * Helpers for module authors (kins_util.c; link it into the module).
 */

/* setup description of a module, as in LinuxCNC's switchkins */
typedef struct kinematics_parms {
    char *sparm;                /* module string parameter (sparm=) */
    char *kinsname;             /* module name, for messages */
    char *halprefix;            /* prefix of the module's pins */
    char *required_coordinates; /* letters the transform needs */
    int max_joints;             /* most joints coordinates= may name */
    int allow_duplicates;       /* may a letter name several joints */
    int fwd_iterates_mask;      /* bit n: type n's forward iterates */
    int gui_kinstype;           /* type shown to GUIs */
} kparms;

/* Parse a coordinates= string ("xyz", "XYYZ", ...): letter n gives joint
   n.  Fills axis_idx_for_jno[0..max_joints-1] with the axis number of
   each joint (0 = X ... 8 = W) or -1 for joints it does not name.
   Returns 0, or -1 after printing why the string is refused (unknown
   letter, too many letters, empty, or a duplicate when not allowed).
   On success the mapping also becomes the module's current mapping, used
   by the three functions below. */
extern int map_coordinates_to_jnumbers(const char *coordinates,
                                       const int max_joints,
                                       const int allow_duplicates,
                                       int axis_idx_for_jno[]);

/* world = joints through the current mapping: each named axis takes the
   value of the first joint with its letter, axes no joint names are 0 */
extern int mapped_joints_to_position(const int max_joints,
                                     const double *joints,
                                     EmcPose *pose);

/* joints = world through the current mapping: every joint of a letter
   (all joints of a gantry axis) gets the axis value; joints beyond the
   mapping are not written */
extern int position_to_mapped_joints(const int max_joints,
                                     const EmcPose *pos,
                                     double *joints);

/* identity kinematics over coordinates= (NULL or "": "xyzabcuvw" cut to
   ksetup_parms->max_joints letters); 0, or -1 after a message */
extern int identityKinematicsSetup(const int comp_id,
                                   const char *coordinates,
                                   kparms *ksetup_parms);
extern int identityKinematicsForward(const double *joint, EmcPose *world,
                                     const KINEMATICS_FORWARD_FLAGS *fflags,
                                     KINEMATICS_INVERSE_FLAGS *iflags);
extern int identityKinematicsInverse(const EmcPose *world, double *joint,
                                     const KINEMATICS_INVERSE_FLAGS *iflags,
                                     KINEMATICS_FORWARD_FLAGS *fflags);

/* number of joints of the current mapping (0 before any) */
extern int kins_mapped_joints(void);

/*
 * For the motion module: pointer types of the exported functions and a
 * helper that looks them all up.
 */
typedef int (*KF)(const double *joint, EmcPose *world,
                  const KINEMATICS_FORWARD_FLAGS *fflags,
                  KINEMATICS_INVERSE_FLAGS *iflags);
typedef int (*KI)(const EmcPose *world, double *joint,
                  const KINEMATICS_INVERSE_FLAGS *iflags,
                  KINEMATICS_FORWARD_FLAGS *fflags);
typedef int (*KH)(EmcPose *world, double *joint,
                  KINEMATICS_FORWARD_FLAGS *fflags,
                  KINEMATICS_INVERSE_FLAGS *iflags);
typedef KINEMATICS_TYPE (*KT)(void);
typedef int (*KS)(void);
typedef int (*KSW)(int switchkins_type);

typedef struct {
    KF forward;
    KI inverse;
    KH home;            /* may be NULL: use forward */
    KT type;
    KS switchable;      /* may be NULL: not switchable */
    KSW kswitch;        /* may be NULL: not switchable */
} kins_funcs_t;

/* Fill k with the functions of the loaded kinematics module (call it in
   rtapi_app_main of the user module, after the kinematics module is
   loaded).  Returns 0, or -1 when a required function (forward,
   inverse, type) is missing, with *missing set to its name. */
static inline int kins_bind(kins_funcs_t *k, const char **missing)
{
    static const char *need[] = {
        "kinematicsForward", "kinematicsInverse", "kinematicsType"
    };
    void *p[3];
    int n;

    for (n = 0; n < 3; n++) {
        p[n] = halsdk_symbol_find(need[n]);
        if (!p[n]) {
            if (missing)
                *missing = need[n];
            return -1;
        }
    }
    k->forward = (KF)p[0];
    k->inverse = (KI)p[1];
    k->type = (KT)p[2];
    k->home = (KH)halsdk_symbol_find("kinematicsHome");
    k->switchable = (KS)halsdk_symbol_find("kinematicsSwitchable");
    k->kswitch = (KSW)halsdk_symbol_find("kinematicsSwitch");
    return 0;
}

#ifdef __cplusplus
}
#endif

#endif /* HALSDK_KINEMATICS_H */
