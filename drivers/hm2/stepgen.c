/*
 * stepgen.c - the HostMot2 step generator and its position loop.
 *
 * Registers: 0 rate (signed; the card adds it to a step accumulator
 * every clock, one step per 2^32), 1 accumulator (read: steps in 16.16
 * fixed point), 2 mode (0 step/dir, 1 up/down, 2 quadrature, 3 table),
 * 3 direction setup, 4 direction hold, 5 step length, 6 step space
 * (times in ticks of the module's clock), 7 table data, 8 table width,
 * 9 the master DDS of the module (written all ones: the full clock).
 *
 * Table mode (step_type 3 to 16: the sequence's length) drives the
 * instance's pins from a table of byte-wide entries, one per phase; the
 * card advances through it one entry per step, forward or back.  The
 * table-data-N params hold four entries each (entry 4N in the low byte).
 * The table data register is a shift register: each write pushes one
 * entry in, so the entries are written one per write, last entry first.
 * They are written when table mode is on and the data, the length or
 * the mode changed (and on a forced write).
 *
 * The card only generates a rate; the position loop is here.  In
 * position mode, each write computes the velocity that reaches the
 * commanded position (plus its feed-forward velocity) within maxvel and
 * maxaccel: the velocity that closes the error in one period, or less
 * when the remaining distance is only enough to decelerate at maxaccel.
 * In velocity mode it follows velocity-cmd within the same limits.
 * Within half a step of the command it only follows the command's own
 * velocity, so a standing axis does not dither around a step edge.
 * maxvel 0 means the fastest the step timings allow; maxaccel 0 means no
 * acceleration limit.  position-fb comes from the accumulator, with
 * finer than step resolution.
 */
#include <errno.h>
#include <math.h>
#include <string.h>

#include "hm2.h"

#define TIMING_MAX 0x3fff         /* ticks: the timing registers' width */
#define TABLE_MAX 16              /* the longest step table */

enum { R_RATE, R_ACCUM, R_MODE, R_DIRSETUP, R_DIRHOLD, R_STEPLEN,
       R_STEPSPACE, R_TABLE, R_TABLEWIDTH, R_MASTER_DDS };

#define PIN(kind, dir, field, suffix)                                      \
    if (!r)                                                                \
        r = hal_pin_##kind##_newf(dir, &s->field, comp_id,                 \
                                  "%s.stepgen.%02d." suffix, b->name, i)
#define PARAM(kind, field, suffix)                                         \
    if (!r)                                                                \
        r = hal_param_##kind##_newf(HAL_RW, &s->field, comp_id,            \
                                    "%s.stepgen.%02d." suffix, b->name, i)

int hm2_stepgen_setup(struct hm2_board *b, int comp_id)
{
    struct hm2_stepgen *sg = &b->sg;
    int i, r = 0;

    if (sg->num == 0)
        return 0;
    sg->md = hm2_find_module(b, HM2_GTAG_STEPGEN);
    sg->clock_hz = sg->md->clock_hz;
    sg->inst = hal_malloc(sizeof(*sg->inst) * (size_t)sg->num);
    if (sg->inst == NULL)
        return -ENOMEM;
    memset(sg->inst, 0, sizeof(*sg->inst) * (size_t)sg->num);
    for (i = 0; i < sg->num && r == 0; i++) {
        struct hm2_stepgen_inst *s = &sg->inst[i];
        PIN(float, HAL_IN, position_cmd, "position-cmd");
        PIN(float, HAL_IN, velocity_cmd, "velocity-cmd");
        PIN(s32, HAL_OUT, counts, "counts");
        PIN(float, HAL_OUT, position_fb, "position-fb");
        PIN(float, HAL_OUT, velocity_fb, "velocity-fb");
        PIN(bit, HAL_IN, enable, "enable");
        PIN(bit, HAL_IN, control_type, "control-type");
        PIN(bit, HAL_IN, position_reset, "position-reset");
        PARAM(float, position_scale, "position-scale");
        PARAM(float, maxvel, "maxvel");
        PARAM(float, maxaccel, "maxaccel");
        PARAM(u32, steplen, "steplen");
        PARAM(u32, stepspace, "stepspace");
        PARAM(u32, dirsetup, "dirsetup");
        PARAM(u32, dirhold, "dirhold");
        PARAM(u32, step_type, "step_type");
        PARAM(u32, table_data[0], "table-data-0");
        PARAM(u32, table_data[1], "table-data-1");
        PARAM(u32, table_data[2], "table-data-2");
        PARAM(u32, table_data[3], "table-data-3");
        PIN(float, HAL_OUT, dbg_ff_vel, "dbg_ff_vel");
        PIN(float, HAL_OUT, dbg_vel_error, "dbg_vel_error");
        PIN(float, HAL_OUT, dbg_s_to_match, "dbg_s_to_match");
        PIN(float, HAL_OUT, dbg_err_at_match, "dbg_err_at_match");
        PIN(float, HAL_OUT, dbg_pos_minus_prev_cmd, "dbg_pos_minus_prev_cmd");
        PIN(s32, HAL_OUT, dbg_step_rate, "dbg_step_rate");
        if (r)
            break;
        s->position_scale = 1.0;
        s->maxvel = 0.0;
        s->maxaccel = 1.0;
        /* the timings start at the longest the registers hold, as the
           reference's do: safe for any drive until they are set */
        s->steplen = s->stepspace = s->dirsetup = s->dirhold =
            (u32)(TIMING_MAX * 1e9 / sg->clock_hz);
        s->step_type = 0;
    }
    if (r < 0)
        return r;
    return hm2_read_regs(b, sg->md, R_ACCUM, sg->num, sg->accum);
}

void hm2_stepgen_process(struct hm2_board *b, long period)
{
    struct hm2_stepgen *sg = &b->sg;
    int i;
    (void)period;
    for (i = 0; i < sg->num; i++) {
        struct hm2_stepgen_inst *s = &sg->inst[i];
        u32 acc = sg->accum[i];
        double scale = s->position_scale == 0.0 ? 1.0 : s->position_scale;
        if (!s->primed) {
            s->total_counts = 0;    /* position 0 at load */
            s->primed = 1;
        } else {
            s->total_counts += (s32)(acc - s->last_acc);
        }
        s->last_acc = acc;
        if (*s->position_reset)
            s->zero = s->total_counts;
        s->fb_pos = (double)(s->total_counts - s->zero) / 65536.0 / scale;
        *s->counts = (s32)((s->total_counts - s->zero) >> 16);
        *s->position_fb = s->fb_pos;
    }
}

static u32 ticks(u32 ns, u32 clock_hz)
{
    double t = ceil((double)ns * clock_hz / 1e9);
    if (t > TIMING_MAX)
        t = TIMING_MAX;
    return (u32)t;
}

static double max_step_rate(struct hm2_stepgen_inst *s, u32 clock_hz)
{
    double ns = (double)s->steplen + (double)s->stepspace;
    double max_rate = clock_hz / 2.0;
    if (ns > 0 && 1e9 / ns < max_rate)
        max_rate = 1e9 / ns;
    if (s->step_type == 2)          /* quadrature: four states per step */
        max_rate /= 4;
    return max_rate;
}

static double step_velocity(struct hm2_stepgen_inst *s, double dt,
                            u32 clock_hz)
{
    double scale = s->position_scale == 0.0 ? 1.0 : s->position_scale;
    double vmax = max_step_rate(s, clock_hz) / fabs(scale);
    double a = s->maxaccel, target;

    if (s->maxvel > 0 && s->maxvel < vmax)
        vmax = s->maxvel;
    if (*s->control_type) {
        target = *s->velocity_cmd;
        s->old_pos_cmd = *s->position_cmd;
    } else {
        double cmd = *s->position_cmd;
        double ff = (cmd - s->old_pos_cmd) / dt;
        double err = cmd - s->fb_pos, fix = fabs(err) / dt;
        *s->dbg_pos_minus_prev_cmd = s->fb_pos - s->old_pos_cmd;
        *s->dbg_ff_vel = ff;
        *s->dbg_err_at_match = err;
        s->old_pos_cmd = cmd;
        if (fabs(err) < 0.5 / fabs(scale))
            fix = 0.0;      /* within half a step: no dither around it */
        else if (a > 0) {
            /* no faster than what still stops at the target, relative
               to the moving command */
            double stop = sqrt(2.0 * a * fabs(err));
            if (stop < fix)
                fix = stop;
        }
        target = ff + (err < 0 ? -fix : fix);
    }
    if (target > vmax)
        target = vmax;
    if (target < -vmax)
        target = -vmax;
    *s->dbg_vel_error = target - s->cur_vel;
    *s->dbg_s_to_match = a > 0 ? fabs(target - s->cur_vel) / a : 0.0;
    if (a > 0) {
        if (target > s->cur_vel + a * dt)
            target = s->cur_vel + a * dt;
        if (target < s->cur_vel - a * dt)
            target = s->cur_vel - a * dt;
    }
    return target;
}

/* the table's length: step_type, at most TABLE_MAX */
static u32 table_len(const struct hm2_stepgen_inst *s)
{
    return s->step_type > TABLE_MAX ? TABLE_MAX : s->step_type;
}

/* in table mode, push the table into instance i's table data register
   when it changed (or when the mode registers were just written) */
static void write_table(struct hm2_board *b, int i, int force)
{
    struct hm2_stepgen *sg = &b->sg;
    struct hm2_stepgen_inst *s = &sg->inst[i];
    u16 addr;
    u32 n, j;
    int changed = force;

    if (s->step_type < 3) {
        s->w_table_len = 0;     /* leaving table mode: rewrite on return */
        return;
    }
    n = table_len(s);
    for (j = 0; j < 4; j++)
        if (s->table_data[j] != s->w_table[j])
            changed = 1;
    if (n != s->w_table_len)
        changed = 1;
    if (!changed)
        return;
    addr = (u16)(hm2_reg_addr(sg->md, R_TABLE) + i * sg->md->instance_stride);
    for (j = n; j-- > 0;) {
        u32 entry = (s->table_data[j / 4] >> (8 * (j % 4))) & 0xffu;
        hm2_queue_write(b, addr, &entry, 1);
    }
    for (j = 0; j < 4; j++)
        s->w_table[j] = s->table_data[j];
    s->w_table_len = n;
}

void hm2_stepgen_prepare(struct hm2_board *b, long period)
{
    struct hm2_stepgen *sg = &b->sg;
    double dt = period > 0 ? period * 1e-9 : 1e-3;
    int i, timing = 0;
    u32 steplen[HM2_MAX_INST], stepspace[HM2_MAX_INST],
        dirsetup[HM2_MAX_INST], dirhold[HM2_MAX_INST], mode[HM2_MAX_INST],
        width[HM2_MAX_INST];

    if (sg->num == 0)
        return;
    for (i = 0; i < sg->num; i++) {
        struct hm2_stepgen_inst *s = &sg->inst[i];
        double scale = s->position_scale == 0.0 ? 1.0 : s->position_scale;
        double rate;
        if (!*s->enable) {
            s->cur_vel = 0.0;
            s->old_pos_cmd = *s->position_cmd;
        } else {
            s->cur_vel = step_velocity(s, dt, sg->clock_hz);
        }
        *s->velocity_fb = s->cur_vel;
        rate = s->cur_vel * scale * 4294967296.0 / sg->clock_hz;
        if (rate > 2147483647.0)
            rate = 2147483647.0;
        if (rate < -2147483647.0)
            rate = -2147483647.0;
        sg->rate[i] = (u32)(s32)lrint(rate);
        *s->dbg_step_rate = (s32)sg->rate[i];

        steplen[i] = ticks(s->steplen, sg->clock_hz);
        stepspace[i] = ticks(s->stepspace, sg->clock_hz);
        dirsetup[i] = ticks(s->dirsetup, sg->clock_hz);
        dirhold[i] = ticks(s->dirhold, sg->clock_hz);
        /* as the reference's driver writes them: table mode is the
           step type with its two low bits set, the width the table's
           last index */
        mode[i] = s->step_type >= 3 ? (s->step_type | 3) : s->step_type;
        width[i] = s->step_type >= 3 ? table_len(s) - 1 : 0;
        if (steplen[i] != s->w_steplen || stepspace[i] != s->w_stepspace
            || dirsetup[i] != s->w_dirsetup || dirhold[i] != s->w_dirhold
            || mode[i] != s->w_mode || width[i] != s->w_width
            || !s->timing_written)
            timing = 1;
    }
    if (timing || b->force_write) {
        hm2_write_regs(b, sg->md, R_MODE, sg->num, mode);
        hm2_write_regs(b, sg->md, R_DIRSETUP, sg->num, dirsetup);
        hm2_write_regs(b, sg->md, R_DIRHOLD, sg->num, dirhold);
        hm2_write_regs(b, sg->md, R_STEPLEN, sg->num, steplen);
        hm2_write_regs(b, sg->md, R_STEPSPACE, sg->num, stepspace);
        if (sg->md->num_registers > R_TABLEWIDTH)
            hm2_write_regs(b, sg->md, R_TABLEWIDTH, sg->num, width);
        if (sg->md->num_registers > R_MASTER_DDS) {
            u32 dds = 0xffffffffu;
            hm2_queue_write(b, hm2_reg_addr(sg->md, R_MASTER_DDS), &dds, 1);
        }
        for (i = 0; i < sg->num; i++) {
            struct hm2_stepgen_inst *s = &sg->inst[i];
            s->w_steplen = steplen[i];
            s->w_stepspace = stepspace[i];
            s->w_dirsetup = dirsetup[i];
            s->w_dirhold = dirhold[i];
            s->w_mode = mode[i];
            s->w_width = width[i];
            s->timing_written = 1;
        }
    }
    if (sg->md->num_registers > R_TABLE) {
        for (i = 0; i < sg->num; i++)
            write_table(b, i, timing || b->force_write);
    }
    hm2_write_regs(b, sg->md, R_RATE, sg->num, sg->rate);
}
