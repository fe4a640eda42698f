/*
 * pwmgen.c - the HostMot2 PWM generator.
 *
 * Registers: 0 value (per instance: duty in bits 16..30 scaled to the
 * PWM width, bit 31 the direction), 1 mode (per instance: bits 0..1 the
 * width, 9 + n bits; bits 3..4 the output type - 1; bit 5 double
 * buffered, as the reference sets it), 2 the
 * PWM master rate (one for the module), 3 the PDM master rate, 4 enable
 * (bit n: instance n enabled).
 *
 * value / scale is the duty cycle, clamped to -1..1; output-type is that
 * of hostmot2(9): 1 PWM/direction, 2 up/down, 3 PDM/direction,
 * 4 direction/PWM.  offset-mode maps -1..1 to 0..100 %.
 */
#include <errno.h>
#include <math.h>
#include <string.h>

#include "hm2.h"

enum { R_VALUE, R_MODE, R_PWM_RATE, R_PDM_RATE, R_ENABLE };
#define PWM_BITS 12
#define MODE_DOUBLE_BUFFER (1u << 5)

#define PIN(kind, dir, field, suffix)                                      \
    if (!r)                                                                \
        r = hal_pin_##kind##_newf(dir, &p->field, comp_id,                 \
                                  "%s.pwmgen.%02d." suffix, b->name, i)
#define PARAM(kind, field, suffix)                                         \
    if (!r)                                                                \
        r = hal_param_##kind##_newf(HAL_RW, &p->field, comp_id,            \
                                    "%s.pwmgen.%02d." suffix, b->name, i)

int hm2_pwmgen_setup(struct hm2_board *b, int comp_id)
{
    struct hm2_pwmgen *pw = &b->pwm;
    int i, r = 0;

    if (pw->num == 0)
        return 0;
    pw->md = hm2_find_module(b, HM2_GTAG_PWMGEN);
    pw->clock_hz = pw->md->clock_hz;
    pw->inst = hal_malloc(sizeof(*pw->inst) * (size_t)pw->num);
    if (pw->inst == NULL)
        return -ENOMEM;
    memset(pw->inst, 0, sizeof(*pw->inst) * (size_t)pw->num);
    for (i = 0; i < pw->num && r == 0; i++) {
        struct hm2_pwmgen_inst *p = &pw->inst[i];
        PIN(float, HAL_IN, value, "value");
        PIN(bit, HAL_IN, enable, "enable");
        PARAM(float, scale, "scale");
        PARAM(s32, output_type, "output-type");
        PARAM(bit, offset_mode, "offset-mode");
        p->scale = 1.0;
        p->output_type = 1;
    }
    if (!r)
        r = hal_param_u32_newf(HAL_RW, &pw->pwm_frequency, comp_id,
                               "%s.pwmgen.pwm_frequency", b->name);
    if (!r)
        r = hal_param_u32_newf(HAL_RW, &pw->pdm_frequency, comp_id,
                               "%s.pwmgen.pdm_frequency", b->name);
    pw->pwm_frequency = 20000;
    pw->pdm_frequency = 20000;
    return r;
}

static u32 rate_reg(u32 freq, u32 clock_hz, int bits)
{
    /* DDS: the PWM counter of 2^bits steps advances by rate / 65536 per
       clock */
    double v = (double)freq * 65536.0 * (double)(1u << bits) / clock_hz;
    if (v > 65535.0)
        v = 65535.0;
    if (v < 1.0)
        v = 1.0;
    return (u32)v;
}

void hm2_pwmgen_prepare(struct hm2_board *b)
{
    struct hm2_pwmgen *pw = &b->pwm;
    int i, dirty = b->force_write;
    u32 en = 0, v;
    if (pw->num == 0)
        return;
    for (i = 0; i < pw->num; i++) {
        struct hm2_pwmgen_inst *p = &pw->inst[i];
        double scale = p->scale == 0.0 ? 1.0 : p->scale;
        double dc = *p->value / scale;
        int type = p->output_type;
        u32 mode, mag;
        if (dc > 1.0)
            dc = 1.0;
        if (dc < -1.0)
            dc = -1.0;
        if (p->offset_mode)
            dc = (dc + 1.0) / 2.0;
        if (type < 1 || type > 4)
            type = 1;
        mode = (PWM_BITS - 9) | ((u32)(type - 1) << 3) | MODE_DOUBLE_BUFFER;
        mag = (u32)lrint(fabs(dc) * ((1 << PWM_BITS) - 1));
        pw->value[i] = (mag << 16) | (dc < 0 ? 0x80000000u : 0);
        if (*p->enable)
            en |= 1u << i;
        pw->mode[i] = mode;
        if (mode != pw->w_mode[i])
            dirty = 1;
    }
    if (dirty || pw->pwm_frequency != pw->w_pwm_freq
        || pw->pdm_frequency != pw->w_pdm_freq) {
        hm2_write_regs(b, pw->md, R_MODE, pw->num, pw->mode);
        v = rate_reg(pw->pwm_frequency, pw->clock_hz, PWM_BITS);
        hm2_queue_write(b, hm2_reg_addr(pw->md, R_PWM_RATE), &v, 1);
        v = rate_reg(pw->pdm_frequency, pw->clock_hz, 0);
        hm2_queue_write(b, hm2_reg_addr(pw->md, R_PDM_RATE), &v, 1);
        memcpy(pw->w_mode, pw->mode, sizeof(pw->mode[0]) * (size_t)pw->num);
        pw->w_pwm_freq = pw->pwm_frequency;
        pw->w_pdm_freq = pw->pdm_frequency;
    }
    hm2_write_regs(b, pw->md, R_VALUE, pw->num, pw->value);
    hm2_queue_write(b, hm2_reg_addr(pw->md, R_ENABLE), &en, 1);
}
