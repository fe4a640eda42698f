/*
 * gpio.c - the IOPort module: every I/O pin of the card.
 *
 * Registers (one per port of port_width pins): 0 data (read: the pin
 * levels; write: the levels of GPIO outputs), 1 direction (1: output),
 * 2 alternate source (1: a module drives or reads the pin), 3 open drain,
 * 4 output invert (when the firmware has it; otherwise a GPIO output is
 * inverted here).
 *
 * HAL, per pin NNN (as the reference makes them): every pin has the pins
 * in and in_not (the level on the connector); a plain GPIO also has the
 * pin out and the params is_output, is_opendrain, invert_output; a pin a
 * module drives has is_opendrain and invert_output (shown under their
 * aliases, see pins.c).  The data register is read each cycle
 * and written each cycle; the others when they change.
 */
#include <errno.h>
#include <string.h>

#include "hm2.h"

enum { R_DATA, R_DDR, R_ALT, R_OD, R_INV };

int hm2_gpio_setup(struct hm2_board *b, int comp_id)
{
    struct hm2_ioport *io = &b->ioport;
    int i, r = 0;

    io->md = hm2_find_module(b, HM2_GTAG_IOPORT);
    if (io->md == NULL) {
        HM2_ERR(b, "the firmware has no IOPort module");
        return -ENODEV;
    }
    io->num_ports = (int)b->idrom.io_ports;
    io->width = (int)b->idrom.port_width;
    if (io->num_ports > io->md->instances || io->num_ports > HM2_MAX_INST) {
        HM2_ERR(b, "IDROM: %d I/O ports but %d IOPort instances",
                io->num_ports, io->md->instances);
        return -ENODEV;
    }
    io->pin = hal_malloc(sizeof(*io->pin) * (size_t)b->num_pins);
    if (io->pin == NULL)
        return -ENOMEM;
    memset(io->pin, 0, sizeof(*io->pin) * (size_t)b->num_pins);
    memset(io->ddr, 0, sizeof(io->ddr));
    memset(io->alt, 0, sizeof(io->alt));
    memset(io->module_out, 0, sizeof(io->module_out));

    for (i = 0; i < b->num_pins && r == 0; i++) {
        struct hm2_gpio_hal *g = &io->pin[i];
        const struct hm2_pin *p = &b->pin[i];
        int port = i / io->width, bit = i % io->width;
        int module = p->owner_gtag != 0;
        int module_out = module && (p->sec_pin & 0x80);

        if (module) {
            io->alt[port] |= 1u << bit;
            if (module_out) {
                io->ddr[port] |= 1u << bit;
                io->module_out[port] |= 1u << bit;
            }
        }
        r = hal_pin_bit_newf(HAL_OUT, &g->in, comp_id, "%s.gpio.%03d.in",
                             b->name, i);
        if (!r)
            r = hal_pin_bit_newf(HAL_OUT, &g->in_not, comp_id,
                                 "%s.gpio.%03d.in_not", b->name, i);
        if (!module) {
            if (!r)
                r = hal_pin_bit_newf(HAL_IN, &g->out, comp_id,
                                     "%s.gpio.%03d.out", b->name, i);
            if (!r)
                r = hal_param_bit_newf(HAL_RW, &g->is_output, comp_id,
                                       "%s.gpio.%03d.is_output", b->name, i);
        }
        if (!module || module_out) {
            if (!r)
                r = hal_param_bit_newf(HAL_RW, &g->invert_output, comp_id,
                                       "%s.gpio.%03d.invert_output",
                                       b->name, i);
            if (!r)
                r = hal_param_bit_newf(HAL_RW, &g->is_opendrain, comp_id,
                                       "%s.gpio.%03d.is_opendrain",
                                       b->name, i);
        }
        if (g->in) {
            *g->in = 0;
            *g->in_not = 1;
        }
        if (g->out)
            *g->out = 0;
        g->is_output = 0;
        g->is_opendrain = 0;
        g->invert_output = 0;
    }
    if (r < 0)
        return r;
    return hm2_read_regs(b, io->md, R_DATA, io->num_ports, io->read);
}

void hm2_gpio_process(struct hm2_board *b)
{
    struct hm2_ioport *io = &b->ioport;
    int i;
    for (i = 0; i < b->num_pins; i++) {
        struct hm2_gpio_hal *g = &io->pin[i];
        int level;
        if (g->in == NULL)
            continue;
        level = (io->read[i / io->width] >> (i % io->width)) & 1;
        *g->in = level;
        *g->in_not = !level;
    }
}

void hm2_gpio_prepare(struct hm2_board *b)
{
    struct hm2_ioport *io = &b->ioport;
    int hw_invert = io->md->num_registers > R_INV;
    int i, port, dirty = b->force_write;
    u32 ddr[HM2_MAX_INST], od[HM2_MAX_INST], inv[HM2_MAX_INST];

    for (port = 0; port < io->num_ports; port++) {
        ddr[port] = io->ddr[port];
        od[port] = 0;
        inv[port] = 0;
        io->data[port] = 0;
    }
    for (i = 0; i < b->num_pins; i++) {
        struct hm2_gpio_hal *g = &io->pin[i];
        u32 m = 1u << (i % io->width);
        int out;
        port = i / io->width;
        if (g->out) {                   /* a plain GPIO */
            if (g->is_output)
                ddr[port] |= m;
            out = *g->out != 0;
            if (g->invert_output && !hw_invert)
                out = !out;
            if (out)
                io->data[port] |= m;
        }
        if (g->is_opendrain)
            od[port] |= m;
        if (g->invert_output && hw_invert)
            inv[port] |= m;
    }
    for (port = 0; port < io->num_ports; port++) {
        if (ddr[port] != io->written_ddr[port]
            || od[port] != io->written_od[port]
            || inv[port] != io->written_inv[port])
            dirty = 1;
    }
    if (dirty) {
        hm2_write_regs(b, io->md, R_DDR, io->num_ports, ddr);
        hm2_write_regs(b, io->md, R_ALT, io->num_ports, io->alt);
        if (io->md->num_registers > R_OD)
            hm2_write_regs(b, io->md, R_OD, io->num_ports, od);
        if (hw_invert)
            hm2_write_regs(b, io->md, R_INV, io->num_ports, inv);
        memcpy(io->written_ddr, ddr, sizeof(ddr[0]) * (size_t)io->num_ports);
        memcpy(io->written_od, od, sizeof(od[0]) * (size_t)io->num_ports);
        memcpy(io->written_inv, inv, sizeof(inv[0]) * (size_t)io->num_ports);
    }
    hm2_write_regs(b, io->md, R_DATA, io->num_ports, io->data);
}
