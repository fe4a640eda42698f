/*
 * homing.h - the interface between the motion module and a homing module.
 *
 * Homing is a separate, replaceable realtime module (homemod is the one
 * shipped).  It exports one table, the symbol HALSDK_HOMING_SYMBOL, that
 * motmod looks up when it loads.  motmod runs all functions in the
 * servo thread (or at load time / from its command handler), so a homing
 * module needs no locks.  Functions that refuse something write a reason
 * (a sentence with no trailing period) into why[whylen] and return
 * a negative errno.
 */
#ifndef HALSDK_HOMING_H
#define HALSDK_HOMING_H

#include "mot_joint.h"

#define HALSDK_HOMING_SYMBOL "halsdk_homing_api"
#define HALSDK_HOMING_VERSION 1

/* bits of mot_home_params_t.flags, with the reference's meanings */
#define HOME_IGNORE_LIMITS      0x0001
#define HOME_USE_INDEX          0x0002
#define HOME_IS_SHARED          0x0004
#define HOME_UNLOCK_FIRST       0x0008
#define HOME_ABSOLUTE_ENCODER   0x0010
#define HOME_NO_REHOME          0x0020
#define HOME_NO_FINAL_MOVE      0x0040
#define HOME_INDEX_NO_ENCODER_RESET 0x0080

/* home_sequence of a joint whose HOME_SEQUENCE is not set */
#define HOME_SEQUENCE_NONE (-1000)

/* the [JOINT_n] homing keys of the reference's INI files */
typedef struct {
    double home_offset;         /* HOME_OFFSET: switch/index position */
    double home;                /* HOME: where the final move goes */
    double home_search_vel;     /* HOME_SEARCH_VEL, signed; 0: no search */
    double home_latch_vel;      /* HOME_LATCH_VEL, signed */
    double home_final_vel;      /* HOME_FINAL_VEL; <= 0: joint max vel */
    int home_sequence;          /* HOME_SEQUENCE; HOME_SEQUENCE_NONE
                                   when the key is absent: not in "home
                                   all"; a negative n: sequence |n|,
                                   synchronized */
    int volatile_home;          /* VOLATILE_HOME */
    unsigned flags;             /* HOME_* */
} mot_home_params_t;

typedef struct {
    int version;                /* HALSDK_HOMING_VERSION */

    /* load time: create the pins joint.N.home-sw-in, joint.N.homing,
       joint.N.homed, joint.N.home-state, joint.N.index-enable (and any
       others of the module) under comp_id for the njoints joints;
       nextra of them (the last ones) are extra joints */
    int (*init)(int comp_id, double servo_period, int njoints, int nextra,
                mot_joint_t *joints);

    /* start and end of every servo cycle: pins in and out */
    void (*read_inputs)(void);
    void (*write_outputs)(void);

    /* SET_JOINT_HOMING_PARAMS: check and store */
    int (*set_params)(int joint, const mot_home_params_t *params,
                      char *why, int whylen);

    /* HOME: one joint, or -1 for all joints with a sequence; motmod
       has checked mode, enable and homing-inhibit already */
    int (*start)(int joint, char *why, int whylen);

    /* UNHOME: one joint, -1 all, -2 those with volatile_home */
    int (*unhome)(int joint, char *why, int whylen);

    /* stop every homing move now (ABORT, DISABLE, a fault); joints being
       homed are left unhomed */
    void (*abort)(void);

    /* once per servo cycle, after read_inputs; returns 1 while any
       joint homes */
    int (*run)(void);

    int (*is_homed)(int joint);
    int (*is_homing)(int joint);
    int (*all_homed)(void);     /* all joints, extra joints included */
    int (*state)(int joint);    /* the number on joint.N.home-state */

    /* limits of this joint are not checked now (HOME_IGNORE_LIMITS
       during its search) */
    int (*ignores_limits)(int joint);

    /* returns the last failure text ("" if none) and clears it: motmod
       reports it as a motion error */
    const char *(*take_error)(void);
} mot_homing_api_t;

#endif
