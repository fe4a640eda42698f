/*
 * led.c - the LEDs of the card: one register, LED n (pin CR<n+1>) in
 * bit 31 - n.  The IDROM does not say how many LEDs a card has: it is a
 * property of the board, as in the reference (4 on the Ethernet cards
 * this driver knows; add a board here when it has another number).
 */
#include <errno.h>
#include <string.h>

#include "hm2.h"

static int board_leds(const char *type)
{
    (void)type;
    return 4;
}

int hm2_led_setup(struct hm2_board *b, int comp_id)
{
    struct hm2_led *led = &b->led;
    int i, r = 0, have;

    led->md = hm2_find_module(b, HM2_GTAG_LED);
    if (led->md == NULL || b->cfg.num_leds == 0) {
        led->num = 0;
        return 0;
    }
    have = board_leds(b->type);
    led->num = b->cfg.num_leds < 0 ? have : b->cfg.num_leds;
    if (led->num > have) {
        HM2_ERR(b, "config: num_leds=%d, but the board has %d LEDs",
                led->num, have);
        return -EINVAL;
    }
    led->pin = hal_malloc(sizeof(*led->pin) * (size_t)led->num);
    if (led->pin == NULL)
        return -ENOMEM;
    for (i = 0; i < led->num && r == 0; i++) {
        r = hal_pin_bit_newf(HAL_IN, &led->pin[i], comp_id, "%s.led.CR%02d",
                             b->name, i + 1);
        if (!r)
            *led->pin[i] = 0;
    }
    return r;
}

void hm2_led_prepare(struct hm2_board *b)
{
    struct hm2_led *led = &b->led;
    u32 v = 0;
    int i;
    if (led->num == 0)
        return;
    for (i = 0; i < led->num; i++)
        if (*led->pin[i])
            v |= 1u << (31 - i);
    if (v == led->w_reg && led->written && !b->force_write)
        return;
    hm2_queue_write(b, hm2_reg_addr(led->md, 0), &v, 1);
    led->w_reg = v;
    led->written = 1;
}
