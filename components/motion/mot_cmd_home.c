/*
 * mot_cmd_home.c - the homing commands: HOME, UNHOME and
 * SET_JOINT_HOMING_PARAMS (the homing module, homing.h, does the work).
 */
#include "rtapi.h"
#include "rtapi_math.h"
#include "rtapi_string.h"
#include "hal.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <math.h>

#include "mot_priv.h"
#include "mot_cmd.h"

/* ---- homing ---- */
int mot_cmd_home(mot_t *mot, const mot_command_t *c)
{
    int r, i;
    char w[MOT_REASON_LEN];

    if (mot->mode != MOT_MODE_FREE)
        return mot_reject(mot, "HOME needs free mode (now %s)",
                          mot_mode_names[mot->mode]);
    if (!mot->enabled)
        return mot_reject(mot, "HOME needs motion enabled");
    if (*mot->mp->homing_inhibit)
        return mot_reject(mot, "HOME: homing is inhibited "
                          "(motion.homing-inhibit is true)");
    if (c->joint != -1 && (r = mot_bad_joint(mot, c->joint)))
        return r;
    for (i = 0; i < mot->num_joints_used; i++) {
        if ((c->joint == -1 || c->joint == i)
            && mot->joints[i].free_tp.active && !mot->home->is_homing(i))
            return mot_reject(mot, "HOME: joint %d is moving (wait until it "
                              "stops)", i);
    }
    w[0] = 0;
    r = mot->home->start(c->joint, w, sizeof(w));
    if (r < 0)
        return mot_reject(mot, "HOME: %s",
                          w[0] ? w : "the homing module refused");
    return MOT_ECHO_ACCEPTED;
}

int mot_cmd_unhome(mot_t *mot, const mot_command_t *c)
{
    int r;
    char w[MOT_REASON_LEN];

    if (c->joint < -2)
        return mot_reject(mot, "UNHOME: joint %d is neither a joint nor -1 "
                          "(all) or -2 (volatile ones)", c->joint);
    if (c->joint >= 0 && (r = mot_bad_joint(mot, c->joint)))
        return r;
    if (mot->mode != MOT_MODE_FREE && c->joint != -2)
        return mot_reject(mot, "UNHOME needs free mode (now %s)",
                          mot_mode_names[mot->mode]);
    /* motion(9): extra joints may be unhomed only while disabled (-2,
       the volatile ones, is left to the homing module) */
    if (mot->enabled && mot->num_extra > 0 && c->joint != -2) {
        int i;
        for (i = mot->num_joints - mot->num_extra; i < mot->num_joints;
             i++)
            if ((c->joint == i || c->joint == -1) && mot->home->is_homed(i))
                return mot_reject(mot, "UNHOME: extra joint %d can be "
                                  "unhomed only while motion is disabled", i);
    }
    w[0] = 0;
    r = mot->home->unhome(c->joint, w, sizeof(w));
    if (r < 0)
        return mot_reject(mot, "UNHOME: %s",
                          w[0] ? w : "the homing module refused");
    return MOT_ECHO_DONE;
}

/* ---- handlers of the dispatch table (mot_command.c) ---- */

/* SET_JOINT_HOMING_PARAMS */
int mot_cmd_set_joint_homing_params(mot_t *mot, const mot_command_t *c)
{
    int r;
    char w[MOT_REASON_LEN];
    mot_home_params_t hp;
    if ((r = mot_bad_joint(mot, c->joint)))
        return r;
    if ((r = mot_bad_pos(mot, "home_offset", c->home_offset))
        || (r = mot_bad_pos(mot, "home", c->home))
        || (r = mot_bad_pos(mot, "home_search_vel", c->home_search_vel))
        || (r = mot_bad_pos(mot, "home_latch_vel", c->home_latch_vel))
        || (r = mot_bad_pos(mot, "home_final_vel", c->home_final_vel)))
        return r;
    if (mot->home->is_homing(c->joint))
        return mot_reject(mot, "SET_JOINT_HOMING_PARAMS: joint %d is homing",
                          c->joint);
    memset(&hp, 0, sizeof(hp));
    hp.home_offset = c->home_offset;
    hp.home = c->home;
    hp.home_search_vel = c->home_search_vel;
    hp.home_latch_vel = c->home_latch_vel;
    hp.home_final_vel = c->home_final_vel;
    hp.home_sequence = c->home_sequence;
    hp.volatile_home = c->volatile_home;
    hp.flags = c->home_flags;
    w[0] = 0;
    if (mot->home->set_params(c->joint, &hp, w, sizeof(w)) < 0)
        return mot_reject(mot, "SET_JOINT_HOMING_PARAMS: %s",
                          w[0] ? w : "the homing module refused");
    mot->home_seq[c->joint] = c->home_sequence;
    return MOT_ECHO_DONE;
}
