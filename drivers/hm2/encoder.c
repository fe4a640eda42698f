/*
 * encoder.c - the HostMot2 quadrature encoder.
 *
 * Registers: 0 counter (bits 0..15 the count, 16..31 a timestamp),
 * 1 latch/control (read: bits 1..3 the filtered A, B and index inputs,
 * bit 15 a quadrature error, bits 16..31 the count latched at the index;
 * write: the mode bits below).  The 16-bit counter is extended here to
 * 64 bits, so it may move up to 32767 counts between two reads.
 *
 * index-enable arms latch-on-index (once); the card clears that bit when
 * the index comes, and the latched count becomes count 0.
 *
 * Velocity comes from the card's timestamps: the counter register holds
 * the time of the last count, the timestamp register (3) the time of the
 * read, both counting at the module clock / (divider + 2), about 2 MHz
 * (10 MHz with hires-timestamp).  A period with counts gives counts /
 * time between the last counts; a period without gives at most one count
 * over the time since the last one, and 0 after vel-timeout seconds.
 */
#include <errno.h>
#include <math.h>
#include <string.h>

#include "hm2.h"

enum { R_COUNTER, R_LATCH, R_TSDIV, R_TSCOUNT, R_RATE };
#define CTRL_QUAD_ERROR (1u << 15)
#define CTRL_FILTER (1u << 11)
#define CTRL_COUNTER_MODE (1u << 10)
#define CTRL_INDEX_MASK (1u << 9)
#define CTRL_INDEX_MASK_POLARITY (1u << 8)
#define CTRL_INDEX_JUSTONCE (1u << 7)
#define CTRL_CLEAR_ON_INDEX (1u << 6)
#define CTRL_LATCH_ON_INDEX (1u << 5)
#define CTRL_INDEX_POLARITY (1u << 4)
#define CTRL_INPUT_INDEX (1u << 3)
#define CTRL_INPUT_B (1u << 2)
#define CTRL_INPUT_A (1u << 1)

#define PIN(kind, dir, field, suffix)                                      \
    if (!r)                                                                \
        r = hal_pin_##kind##_newf(dir, &e->field, comp_id,                 \
                                  "%s.encoder.%02d." suffix, b->name, i)
#define PARAM(kind, field, suffix)                                         \
    if (!r)                                                                \
        r = hal_param_##kind##_newf(HAL_RW, &e->field, comp_id,            \
                                    "%s.encoder.%02d." suffix, b->name, i)

int hm2_encoder_setup(struct hm2_board *b, int comp_id)
{
    struct hm2_encoder *en = &b->enc;
    int i, r = 0;

    if (en->num == 0)
        return 0;
    en->md = hm2_find_module(b, HM2_GTAG_ENCODER);
    en->clock_hz = en->md->clock_hz;
    en->inst = hal_malloc(sizeof(*en->inst) * (size_t)en->num);
    if (en->inst == NULL)
        return -ENOMEM;
    memset(en->inst, 0, sizeof(*en->inst) * (size_t)en->num);
    for (i = 0; i < en->num && r == 0; i++) {
        struct hm2_encoder_inst *e = &en->inst[i];
        PIN(s32, HAL_OUT, count, "count");
        PIN(s32, HAL_OUT, count_latched, "count-latched");
        PIN(s32, HAL_OUT, rawcounts, "rawcounts");
        PIN(s32, HAL_OUT, rawlatch, "rawlatch");
        PIN(float, HAL_OUT, position, "position");
        PIN(float, HAL_OUT, position_latched, "position-latched");
        PIN(float, HAL_OUT, velocity, "velocity");
        PIN(float, HAL_OUT, velocity_rpm, "velocity-rpm");
        PIN(bit, HAL_IN, reset, "reset");
        PIN(bit, HAL_IO, index_enable, "index-enable");
        PIN(bit, HAL_OUT, input_a, "input-a");
        PIN(bit, HAL_OUT, input_b, "input-b");
        PIN(bit, HAL_OUT, input_index, "input-index");
        PIN(bit, HAL_OUT, quad_error, "quad-error");
        PIN(bit, HAL_IN, quad_error_enable, "quad-error-enable");
        PARAM(float, scale, "scale");
        PARAM(bit, index_invert, "index-invert");
        PARAM(bit, index_mask, "index-mask");
        PARAM(bit, index_mask_invert, "index-mask-invert");
        PARAM(bit, counter_mode, "counter-mode");
        PARAM(bit, filter, "filter");
        PARAM(float, vel_timeout, "vel-timeout");
        if (r)
            break;
        e->scale = 1.0;
        e->filter = 1;
        e->vel_timeout = 0.5;
        en->ctrl_dirty[i] = 1;
    }
    if (!r)
        r = hal_pin_bit_newf(HAL_IN, &en->hires_timestamp, comp_id,
                             "%s.encoder.hires-timestamp", b->name);
    if (!r)
        r = hal_pin_u32_newf(HAL_IN, &en->sample_frequency, comp_id,
                             "%s.encoder.sample-frequency", b->name);
    if (r < 0)
        return r;
    *en->hires_timestamp = 0;
    *en->sample_frequency = 25000000;
    r = hm2_read_regs(b, en->md, R_COUNTER, en->num, en->counter);
    if (!r)
        r = hm2_read_regs(b, en->md, R_LATCH, en->num, en->latch);
    if (!r)
        r = hm2_read_regs(b, en->md, R_TSCOUNT, 1, &en->tscount);
    return r;
}

static u32 tsdiv(struct hm2_encoder *en)
{
    u32 freq = *en->hires_timestamp ? 10000000u : 2000000u;
    u32 div = en->clock_hz / freq;
    return div < 2 ? 0 : div - 2;
}

/* counts/s from the timestamps (see above); delta counts this period */
static double ts_velocity(struct hm2_encoder *en,
                          struct hm2_encoder_inst *e, int delta,
                          u16 change_ts, u16 tick, double ts_hz)
{
    double v = *e->velocity * (e->scale == 0.0 ? 1.0 : e->scale);
    if (delta != 0) {
        double span = e->age + (u16)(change_ts - en->last_tscount);
        e->age = (u16)(tick - change_ts);
        return span > 0 ? delta * ts_hz / span : v;
    }
    e->age += (u16)(tick - en->last_tscount);
    if (e->age / ts_hz > e->vel_timeout)
        return 0.0;
    if (fabs(v) > ts_hz / e->age)       /* no count: at most 1 / age */
        v = v > 0 ? ts_hz / e->age : -ts_hz / e->age;
    return v;
}

void hm2_encoder_process(struct hm2_board *b, long period)
{
    struct hm2_encoder *en = &b->enc;
    u16 tick = (u16)en->tscount;
    double ts_hz = (double)en->clock_hz / (en->w_tsdiv + 2);
    int i;
    (void)period;
    for (i = 0; i < en->num; i++) {
        struct hm2_encoder_inst *e = &en->inst[i];
        u16 now = (u16)(en->counter[i] & 0xffff);
        u32 latch = en->latch[i];
        short delta = (short)(u16)(now - e->last);
        double scale = e->scale == 0.0 ? 1.0 : e->scale;
        if (!e->primed) {
            delta = (short)now;     /* the counter read as a signed count */
        }
        /* the index came: latch-on-index armed and now cleared */
        if (e->index_armed == 2 && !(latch & CTRL_LATCH_ON_INDEX)) {
            short to_latch = (short)(u16)((latch >> 16) - e->last);
            long long at = e->total + (e->primed ? to_latch : 0);
            /* the count at the index, then the index is count 0 */
            *e->rawlatch = (s32)at;
            *e->count_latched = (s32)(at - e->zero);
            *e->position_latched = (double)(at - e->zero) / scale;
            e->zero = at;
            if (*e->index_enable)
                *e->index_enable = 0;
            e->index_armed = 0;
            en->ctrl_dirty[i] = 1;
        }
        e->total += delta;
        e->last = now;
        if (*e->reset)
            e->zero = e->total;
        *e->rawcounts = (s32)e->total;
        *e->count = (s32)(e->total - e->zero);
        *e->position = (double)(e->total - e->zero) / scale;
        if (e->primed && en->ts_primed)
            *e->velocity = ts_velocity(en, e, delta,
                                       (u16)(en->counter[i] >> 16), tick,
                                       ts_hz) / scale;
        else
            *e->velocity = 0.0;
        *e->velocity_rpm = *e->velocity * 60.0;
        *e->input_a = (latch & CTRL_INPUT_A) != 0;
        *e->input_b = (latch & CTRL_INPUT_B) != 0;
        *e->input_index = (latch & CTRL_INPUT_INDEX) != 0;
        *e->quad_error = *e->quad_error_enable
            && (latch & CTRL_QUAD_ERROR) != 0;
        e->primed = 1;
    }
    en->last_tscount = tick;
    en->ts_primed = en->num > 0;
}

void hm2_encoder_prepare(struct hm2_board *b)
{
    struct hm2_encoder *en = &b->enc;
    int i, any = 0;
    u32 freq, rate;

    if (en->num == 0)
        return;
    /* the filter's sample clock: the module clock divided by rate + 2 */
    freq = *en->sample_frequency;
    if (freq < 1)
        freq = 1;
    rate = en->clock_hz / freq;
    rate = rate < 2 ? 0 : rate - 2;
    if (rate != en->w_rate || b->force_write) {
        hm2_queue_write(b, hm2_reg_addr(en->md, R_RATE), &rate, 1);
        en->w_rate = rate;
    }
    if (tsdiv(en) != en->w_tsdiv || b->force_write) {
        u32 div = tsdiv(en);
        hm2_queue_write(b, hm2_reg_addr(en->md, R_TSDIV), &div, 1);
        en->w_tsdiv = div;
        en->ts_primed = 0;          /* the next read starts again */
    }
    for (i = 0; i < en->num; i++) {
        struct hm2_encoder_inst *e = &en->inst[i];
        u32 c = 0;
        if (*e->index_enable && !e->index_armed)
            e->index_armed = 1;
        if (!*e->index_enable && e->index_armed)
            e->index_armed = 0;         /* withdrawn by the user */
        if (e->filter)
            c |= CTRL_FILTER;
        if (e->counter_mode)
            c |= CTRL_COUNTER_MODE;
        if (e->index_mask)
            c |= CTRL_INDEX_MASK;
        if (e->index_mask_invert)
            c |= CTRL_INDEX_MASK_POLARITY;
        if (e->index_invert)
            c |= CTRL_INDEX_POLARITY;
        if (e->index_armed)
            c |= CTRL_LATCH_ON_INDEX | CTRL_INDEX_JUSTONCE;
        if (c != e->ctrl_written || en->ctrl_dirty[i] || b->force_write)
            any = 1;
        en->ctrl[i] = c;
    }
    if (!any)
        return;
    hm2_write_regs(b, en->md, R_LATCH, en->num, en->ctrl);
    for (i = 0; i < en->num; i++) {
        struct hm2_encoder_inst *e = &en->inst[i];
        e->ctrl_written = en->ctrl[i];
        en->ctrl_dirty[i] = 0;
        if (e->index_armed == 1)
            e->index_armed = 2;         /* on the card from now on */
    }
}
