/*
 * pins.c - which module instance uses each I/O pin.
 *
 * A pin descriptor names the module (sec_tag), the instance (sec_unit)
 * and the module's pin (sec_pin, bit 7 set when the module drives it)
 * that may use the I/O pin.  A pin goes to its module when that module
 * is supported and the instance is enabled by the config string (for a
 * stepgen, only its first stepgen_width pins); every other pin is a
 * plain GPIO.  The aliases name the output settings of a module's pins
 * after the module (hm2_7i96s.0.stepgen.00.step.invert_output).
 */
#include <stdio.h>

#include "hm2.h"

static int enabled(struct hm2_board *b, int gtag, int inst, int sec_pin)
{
    switch (gtag) {
    case HM2_GTAG_ENCODER:
        return inst < b->enc.num;
    case HM2_GTAG_STEPGEN:
        return inst < b->sg.num && (sec_pin & 0x7f) <= b->sg.width;
    case HM2_GTAG_PWMGEN:
        return inst < b->pwm.num;
    default:
        return 0;
    }
}

int hm2_assign_pins(struct hm2_board *b)
{
    int i;
    for (i = 0; i < b->num_pins; i++) {
        struct hm2_pin *p = &b->pin[i];
        int inst = p->sec_unit & 0x7f;
        p->owner_gtag = 0;
        p->owner_inst = -1;
        if (p->sec_tag && !(p->sec_unit & 0x80)
            && enabled(b, p->sec_tag, inst, p->sec_pin)) {
            p->owner_gtag = p->sec_tag;
            p->owner_inst = inst;
        }
    }
    return 0;
}

/* the HAL name of a module's output pin, as the aliases use it */
static const char *pin_name(int gtag, int sec_pin, char *buf, int len)
{
    int n = sec_pin & 0x7f;
    switch (gtag) {
    case HM2_GTAG_STEPGEN:
        if (n == 1)
            return "step";
        if (n == 2)
            return "direction";
        snprintf(buf, (size_t)len, "table%dpin", n);
        return buf;
    case HM2_GTAG_PWMGEN:
        if (n == 1)
            return "out0";
        if (n == 2)
            return "out1";
        if (n == 3)
            return "enable";
        break;
    }
    snprintf(buf, (size_t)len, "pin%d", n);
    return buf;
}

static const char *module_name(int gtag)
{
    switch (gtag) {
    case HM2_GTAG_ENCODER:
        return "encoder";
    case HM2_GTAG_STEPGEN:
        return "stepgen";
    case HM2_GTAG_PWMGEN:
        return "pwmgen";
    }
    return "module";
}

int hm2_pin_aliases(struct hm2_board *b)
{
    static const char *const what[] = {"invert_output", "is_opendrain"};
    int i, j, k, r;
    for (i = 0; i < b->num_pins; i++) {
        struct hm2_pin *p = &b->pin[i];
        char buf[16], gpio[HAL_NAME_LEN + 1], alias[HAL_NAME_LEN + 1];
        const char *pn;
        int same = 0, nth = 0;
        if (!p->owner_gtag || !(p->sec_pin & 0x80))
            continue;
        pn = pin_name(p->owner_gtag, p->sec_pin, buf, sizeof(buf));
        /* more than one I/O pin for the same module pin: number them */
        for (j = 0; j < b->num_pins; j++) {
            struct hm2_pin *q = &b->pin[j];
            if (q->owner_gtag == p->owner_gtag
                && q->owner_inst == p->owner_inst
                && q->sec_pin == p->sec_pin) {
                if (j < i)
                    nth++;
                same++;
            }
        }
        for (k = 0; k < 2; k++) {
            snprintf(gpio, sizeof(gpio), "%s.gpio.%03d.%s", b->name, i,
                     what[k]);
            if (same > 1)
                snprintf(alias, sizeof(alias), "%s.%s.%02d.%d.%s.%s",
                         b->name, module_name(p->owner_gtag), p->owner_inst,
                         nth, pn, what[k]);
            else
                snprintf(alias, sizeof(alias), "%s.%s.%02d.%s.%s", b->name,
                         module_name(p->owner_gtag), p->owner_inst, pn,
                         what[k]);
            r = hal_param_alias(gpio, alias);
            if (r < 0)
                return r;
        }
    }
    return 0;
}
