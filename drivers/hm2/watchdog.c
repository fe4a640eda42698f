/*
 * watchdog.c - the HostMot2 watchdog.
 *
 * Registers: 0 timer (the timeout, in ticks of the module's clock,
 * minus one; counting down), 1 status (bit 0: the watchdog has bitten;
 * written 0 to clear it), 2 reset (a write of WD_PET restarts the
 * timer).  A bitten card makes every I/O pin an input: its outputs go to
 * their safe state.
 *
 * The watchdog sleeps until the first write function, which writes the
 * timer and from then on pets it each cycle.  When the status says it
 * has bitten, has_bit becomes true and the driver stops writing to the
 * card; the user resets has_bit to false to resume, and the driver then
 * clears the status and writes every setting again.
 */
#include <errno.h>

#include "hm2.h"

enum { R_TIMER, R_STATUS, R_RESET };
#define WD_PET 0x5a000000u
#define WD_DISABLED 0x80000000u     /* a timer with bit 31 set never bites */
#define WD_DEFAULT_TIMEOUT_NS 5000000u

int hm2_watchdog_setup(struct hm2_board *b, int comp_id)
{
    struct hm2_watchdog *wd = &b->wd;
    int r;
    u32 zero = 0, off = WD_DISABLED;

    wd->md = hm2_find_module(b, HM2_GTAG_WATCHDOG);
    wd->present = wd->md != NULL && wd->md->instances > 0;
    if (!wd->present)
        return 0;
    r = hal_pin_bit_newf(HAL_IO, &wd->has_bit, comp_id,
                         "%s.watchdog.has_bit", b->name);
    if (!r)
        r = hal_param_u32_newf(HAL_RW, &wd->timeout_ns, comp_id,
                               "%s.watchdog.timeout_ns", b->name);
    if (r < 0)
        return r;
    *wd->has_bit = 0;
    wd->timeout_ns = WD_DEFAULT_TIMEOUT_NS;
    wd->enabled = 0;
    wd->was_bit = 0;
    /* a watchdog still running from an earlier run (a driver that died)
       would bite between this load and the first write function: stop
       it until then */
    r = lbp16_write32(&b->link, hm2_reg_addr(wd->md, R_TIMER), &off, 1);
    if (r < 0)
        return r;
    /* a card left bitten by an earlier run starts clean */
    r = lbp16_write32(&b->link, hm2_reg_addr(wd->md, R_STATUS), &zero, 1);
    if (r < 0)
        return r;
    return hm2_read_regs(b, wd->md, R_STATUS, 1, &wd->status);
}

/* after a read: a bite sets has_bit (once) */
void hm2_watchdog_process(struct hm2_board *b)
{
    struct hm2_watchdog *wd = &b->wd;
    if (!wd->present || !wd->enabled)
        return;
    if ((wd->status & 1) && !*wd->has_bit && !wd->was_bit) {
        *wd->has_bit = 1;
        HM2_ERR(b, "watchdog has bit! (set the .has_bit pin to False to "
                "resume)");
    }
}

/* true while the watchdog has bitten and the user has not reset it */
int hm2_watchdog_blocked(struct hm2_board *b)
{
    return b->wd.present && *b->wd.has_bit;
}

/* before a write: the timer when it changes, the pet, the reset */
void hm2_watchdog_prepare(struct hm2_board *b)
{
    struct hm2_watchdog *wd = &b->wd;
    u32 v;
    if (!wd->present)
        return;
    if (*wd->has_bit) {
        wd->was_bit = 1;
        return;
    }
    if (wd->was_bit) {
        /* the user reset has_bit: clear the bite, rewrite everything */
        u32 zero = 0;
        hm2_write_regs(b, wd->md, R_STATUS, 1, &zero);
        wd->was_bit = 0;
        wd->status = 0;
        b->force_write = 1;
    }
    if (!wd->enabled || b->force_write
        || wd->timeout_ns != wd->written_timeout) {
        double ticks = (double)wd->timeout_ns * wd->md->clock_hz / 1e9 - 1;
        if (ticks < 1)
            ticks = 1;
        if (ticks > 0x7fffffff)
            ticks = 0x7fffffff;
        v = (u32)ticks;
        hm2_write_regs(b, wd->md, R_TIMER, 1, &v);
        wd->written_timeout = wd->timeout_ns;
        wd->enabled = 1;
    }
    v = WD_PET;
    hm2_write_regs(b, wd->md, R_RESET, 1, &v);
}

/* at unload: the card's outputs go to their safe state at once, rather
   than at the end of the timeout (a card without a watchdog keeps them) */
void hm2_watchdog_bite_now(struct hm2_board *b)
{
    u32 one = 1;
    if (b->wd.present)
        lbp16_write32(&b->link, hm2_reg_addr(b->wd.md, R_TIMER), &one, 1);
}
