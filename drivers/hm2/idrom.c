/*
 * idrom.c - reading the HostMot2 IDROM of the card at load time: the
 * cookie, the IDROM header (clocks, strides, I/O width), the module
 * descriptors and the pin descriptors.  Everything the driver creates
 * comes from here, as on a real card.
 */
#include <errno.h>
#include <string.h>

#include "hm2.h"

#define MD_SIZE 12

int hm2_read_idrom(struct hm2_board *b)
{
    u32 w[16], cookie, offset, raw[HM2_MAX_MODULES * 3];
    u32 pins[HM2_MAX_PINS];
    struct hm2_idrom *id = &b->idrom;
    int r, i;

    r = lbp16_read32(&b->link, HM2_ADDR_COOKIE, &cookie, 1);
    if (r < 0)
        return r;
    if (cookie != HM2_COOKIE) {
        HM2_ERR(b, "bad HostMot2 cookie 0x%08x (expected 0x%08x): is "
                "the card running HostMot2 firmware?", cookie, HM2_COOKIE);
        return -ENODEV;
    }
    r = lbp16_read32(&b->link, HM2_ADDR_IDROM_OFFSET, &offset, 1);
    if (r < 0)
        return r;
    if (offset == 0 || offset > 0xff00) {
        HM2_ERR(b, "bad IDROM offset 0x%08x", offset);
        return -ENODEV;
    }
    r = lbp16_read32(&b->link, (u16)offset, w, 16);
    if (r < 0)
        return r;
    id->idrom_type = w[0];
    id->offset_to_modules = w[1];
    id->offset_to_pin_desc = w[2];
    memcpy(id->board_name, &w[3], 8);
    id->board_name[8] = 0;
    id->fpga_size = w[5];
    id->fpga_pins = w[6];
    id->io_ports = w[7];
    id->io_width = w[8];
    id->port_width = w[9];
    id->clock_low = w[10];
    id->clock_high = w[11];
    id->instance_stride_0 = w[12];
    id->instance_stride_1 = w[13];
    id->register_stride_0 = w[14];
    id->register_stride_1 = w[15];
    if (id->idrom_type != 2 && id->idrom_type != 3) {
        HM2_ERR(b, "IDROM type %u is not supported (2 or 3 expected)",
                id->idrom_type);
        return -ENODEV;
    }
    if (id->io_width == 0 || id->io_width > HM2_MAX_PINS
        || id->port_width == 0 || id->port_width > 32
        || id->io_ports * id->port_width != id->io_width) {
        HM2_ERR(b, "bad IDROM: %u ports of %u pins for %u I/O pins",
                id->io_ports, id->port_width, id->io_width);
        return -ENODEV;
    }
    if (id->clock_low == 0 || id->clock_high == 0) {
        HM2_ERR(b, "bad IDROM: a clock of 0 Hz");
        return -ENODEV;
    }

    r = lbp16_read32(&b->link, (u16)(offset + id->offset_to_modules), raw,
                     HM2_MAX_MODULES * 3);
    if (r < 0)
        return r;
    b->num_md = 0;
    for (i = 0; i < HM2_MAX_MODULES; i++) {
        const u8 *d = (const u8 *)&raw[i * 3];
        struct hm2_module_desc *md = &b->md[b->num_md];
        if (d[0] == 0)
            break;
        md->gtag = d[0];
        md->version = d[1];
        md->clock_tag = d[2];
        md->instances = d[3];
        md->base_address = (u16)(d[4] | (d[5] << 8));
        md->num_registers = d[6];
        md->strides = d[7];
        md->multiple_registers = raw[i * 3 + 2];
        md->clock_hz = md->clock_tag == 2 ? id->clock_high : id->clock_low;
        md->register_stride = (md->strides & 0x0f) == 0
            ? id->register_stride_0 : id->register_stride_1;
        md->instance_stride = (md->strides & 0xf0) == 0
            ? id->instance_stride_0 : id->instance_stride_1;
        b->num_md++;
    }

    r = lbp16_read32(&b->link, (u16)(offset + id->offset_to_pin_desc), pins,
                     (int)id->io_width);
    if (r < 0)
        return r;
    b->num_pins = (int)id->io_width;
    for (i = 0; i < b->num_pins; i++) {
        const u8 *d = (const u8 *)&pins[i];
        b->pin[i].sec_pin = d[0];
        b->pin[i].sec_tag = d[1];
        b->pin[i].sec_unit = d[2];
        b->pin[i].primary_tag = d[3];
        b->pin[i].owner_gtag = 0;
        b->pin[i].owner_inst = -1;
    }
    return 0;
}

struct hm2_module_desc *hm2_find_module(struct hm2_board *b, int gtag)
{
    int i;
    for (i = 0; i < b->num_md; i++)
        if (b->md[i].gtag == gtag)
            return &b->md[i];
    return NULL;
}

/* the address of register reg of instance 0 */
u16 hm2_reg_addr(const struct hm2_module_desc *md, int reg)
{
    return (u16)(md->base_address + reg * md->register_stride);
}
