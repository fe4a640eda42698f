/*
 * mot_cmd_spindle.c - the spindle commands (SPINDLE_ON, _OFF, _INCREASE,
 * _DECREASE, _ORIENT, _BRAKE_ENGAGE, _BRAKE_RELEASE) and stopping the
 * spindles on DISABLE and faults.
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

static int any_spindle_on(mot_t *mot)
{
    int i;
    for (i = 0; i < mot->num_spindles; i++)
        if (mot->spindle[i].on && mot->spindle[i].speed != 0)
            return 1;
    return 0;
}

/* a new speed or direction: the next feed move waits for at-speed */
static void spindle_changed(mot_t *mot, mot_spindle_t *sp, double old)
{
    if (sp->speed != old)
        mot->wait_at_speed = 1;
}

int mot_cmd_spindle(mot_t *mot, const mot_command_t *c)
{
    const char *name = mot_cmd_name(c->cmd);
    mot_spindle_t *sp;
    int r, n = c->index;
    double old, step;

    if ((r = mot_bad_spindle(mot, n)))
        return r;
    sp = &mot->spindle[n];
    old = sp->on ? sp->speed : 0.0;
    switch (c->cmd) {
    case MOT_CMD_SPINDLE_ON:
        if (!mot->enabled)
            return mot_reject(mot, "SPINDLE_ON needs motion enabled");
        if ((r = mot_bad_pos(mot, "spindle speed", c->vel)))
            return r;
        if (c->value != 0) {
            if ((r = mot_bad_positive(mot, "CSS surface speed", c->value))
                || (r = mot_bad_nonneg(mot, "CSS maximum speed", c->offset)))
                return r;
            if (c->ival < 0 || c->ival >= MOT_MAX_AXES)
                return mot_reject(mot, "SPINDLE_ON: CSS axis %d does not "
                                  "exist (axes are 0..8 for X..W)", c->ival);
        }
        if (*mot->sp[n].amp_fault_in)
            return mot_reject(mot, "SPINDLE_ON: spindle %d has an amplifier "
                              "fault (spindle.%d.amp-fault-in is true)", n, n);
        sp->speed = c->vel;
        sp->css_factor = c->value;
        sp->css_axis = c->ival;
        sp->css_max = c->offset;
        sp->on = 1;
        sp->brake = 0;
        sp->orient_state = MOT_ORIENT_NONE;
        sp->amp_fault = 0;
        spindle_changed(mot, sp, old);
        if (!old)
            mot->wait_at_speed = 1;
        return MOT_ECHO_DONE;

    case MOT_CMD_SPINDLE_OFF:
        sp->speed = 0.0;
        sp->css_factor = 0.0;
        sp->on = 0;
        sp->brake = 1;
        sp->orient_state = MOT_ORIENT_NONE;
        if (!any_spindle_on(mot))
            mot->wait_at_speed = 0;     /* nothing left to wait for */
        return MOT_ECHO_DONE;

    case MOT_CMD_SPINDLE_INCREASE:
    case MOT_CMD_SPINDLE_DECREASE:
        if ((r = mot_bad_nonneg(mot, "speed step", c->value)))
            return r;
        if (!sp->on || sp->speed == 0)
            return mot_reject(mot, "%s: spindle %d is off", name, n);
        step = c->value > 0 ? c->value : 0.1 * fabs(sp->speed);
        if (c->cmd == MOT_CMD_SPINDLE_DECREASE) {
            if (step >= fabs(sp->speed))
                return mot_reject(mot, "SPINDLE_DECREASE: a step of %g rpm "
                                  "would stop spindle %d (now %g rpm); use "
                                  "SPINDLE_OFF", step, n, sp->speed);
            step = -step;
        }
        sp->speed += sp->speed > 0 ? step : -step;
        spindle_changed(mot, sp, old);
        return MOT_ECHO_DONE;

    case MOT_CMD_SPINDLE_ORIENT:
        if (!mot->enabled)
            return mot_reject(mot, "SPINDLE_ORIENT needs motion enabled");
        if ((r = mot_bad_pos(mot, "orient angle", c->value)))
            return r;
        sp->speed = 0.0;
        sp->css_factor = 0.0;
        sp->on = 0;
        sp->brake = 0;
        sp->orient_angle = c->value;
        sp->orient_mode = c->ival;
        sp->orient_fault = 0;
        sp->orient_state = MOT_ORIENT_RUNNING;
        return MOT_ECHO_ACCEPTED;

    case MOT_CMD_SPINDLE_BRAKE_ENGAGE:
        if (sp->on && sp->speed != 0)
            return mot_reject(mot, "SPINDLE_BRAKE_ENGAGE: spindle %d turns "
                              "(%g rpm); send SPINDLE_OFF first", n,
                              sp->speed);
        sp->brake = 1;
        return MOT_ECHO_DONE;

    case MOT_CMD_SPINDLE_BRAKE_RELEASE:
        sp->brake = 0;
        return MOT_ECHO_DONE;
    }
    return mot_reject(mot, "%s is not a spindle command", name);
}

void mot_spindles_stop(mot_t *mot)
{
    int i;
    mot->wait_at_speed = 0;
    for (i = 0; i < mot->num_spindles; i++) {
        mot_spindle_t *sp = &mot->spindle[i];
        if (sp->on) {
            sp->brake = 1;
        }
        sp->speed = 0.0;
        sp->css_factor = 0.0;
        sp->on = 0;
        if (sp->orient_state == MOT_ORIENT_RUNNING)
            sp->orient_state = MOT_ORIENT_NONE;
        if (sp->index_armed) {
            *mot->sp[i].index_enable = 0;
            sp->index_armed = 0;
        }
    }
}
