/*
 * hm2_eth.c - the realtime module hm2_eth: Mesa Ethernet cards with
 * HostMot2 firmware.
 *
 *     loadrt hm2_eth board_ip=10.10.10.10 config="num_encoders=1"
 *
 * Modparams as the reference's: board_ip (one per board; "ip:port"
 * reaches a card, such as the simulated one, on another UDP port than
 * 27181), config (one hostmot2 config string per board), board_mac
 * (accepted; the reference makes static ARP entries with it, halsdk
 * does not) and debug.
 *
 * Per board it makes the functions hm2_<type>.<n>.read, .write and
 * .read-request and the packet-error pins and params of hm2_eth(9).
 * read-request sends the read packet (built once at load); read waits a
 * bounded time for its answer (packet-read-timeout), then each module
 * turns the registers into pins; write builds one packet of writes from
 * the pins and sends it.  A cycle whose answer is lost, late or of the
 * wrong size, or whose send fails, is a packet error: packet-error is
 * true for that cycle, packet-error-level rises by
 * packet-error-increment (and falls by packet-error-decrement in a good
 * cycle), and at packet-error-limit the board stops (io_error) until the
 * user resets io_error.
 */
#include <errno.h>
#include <string.h>

#include "rtapi_app.h"
#include "hm2.h"

MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("Mesa Ethernet cards with HostMot2 firmware");
MODULE_LICENSE("GPL");

static char *board_ip[HM2_MAX_BOARDS] = {0};
RTAPI_MP_ARRAY_STRING(board_ip, HM2_MAX_BOARDS,
                      "IP address of the board(s) (ip or ip:port)");
static char *config[HM2_MAX_BOARDS] = {0};
RTAPI_MP_ARRAY_STRING(config, HM2_MAX_BOARDS,
                      "hostmot2 config strings, one per board");
static char *board_mac[HM2_MAX_BOARDS] = {0};
RTAPI_MP_ARRAY_STRING(board_mac, HM2_MAX_BOARDS,
                      "MAC address of the board(s) (accepted, unused: "
                      "halsdk sets no ARP entry)");
static int debug = 0;
RTAPI_MP_INT(debug, "print the IDROM and the pin use at load");

static int comp_id = -1;
static struct hm2_board *boards[HM2_MAX_BOARDS];
static int num_boards;

/* ------------------------------------------------------------ helpers */

int hm2_add_region(struct hm2_board *b, u16 addr, int count, u32 *dst)
{
    while (count > 0) {
        int n = count > LBP16_COUNT_MAX ? LBP16_COUNT_MAX : count;
        struct hm2_region *rg;
        if (b->num_regions >= HM2_MAX_REGIONS
            || lbp16_pkt_read(&b->rdreq, LBP16_SPACE_HM2, 1, addr, n) < 0) {
            HM2_ERR(b, "too many registers to read in one packet");
            return -ENOSPC;
        }
        rg = &b->region[b->num_regions++];
        rg->addr = addr;
        rg->count = (u16)n;
        rg->dst = dst;
        addr += 4 * n;
        dst += n;
        count -= n;
    }
    return 0;
}

int hm2_read_regs(struct hm2_board *b, const struct hm2_module_desc *md,
                  int reg, int n, u32 *dst)
{
    u16 addr;
    int i, r;
    if (n <= 0)
        return 0;
    addr = hm2_reg_addr(md, reg);
    if (md->instance_stride == 4)
        return hm2_add_region(b, addr, n, dst);
    for (i = 0; i < n; i++) {
        r = hm2_add_region(b, (u16)(addr + i * md->instance_stride), 1,
                           dst + i);
        if (r < 0)
            return r;
    }
    return 0;
}

/* send a packet of the thread functions: counted, as the card counts
   the datagrams it receives; a failed send is a packet error */
void hm2_send(struct hm2_board *b, const struct lbp16_pkt *p)
{
    if (p->len == 0)
        return;
    if (lbp16_send(&b->link, p) < 0)
        b->cycle_error = 1;
    else
        b->tx_count++;
}

/* append to the write packet; a full packet is sent and a new begun */
void hm2_queue_write(struct hm2_board *b, u16 addr, const u32 *data,
                     int count)
{
    while (count > 0) {
        int n = count > 64 ? 64 : count;
        if (lbp16_pkt_write32(&b->wr, addr, data, n) < 0) {
            hm2_send(b, &b->wr);
            lbp16_pkt_reset(&b->wr);
            if (lbp16_pkt_write32(&b->wr, addr, data, n) < 0)
                return;
        }
        addr += 4 * n;
        data += n;
        count -= n;
    }
}

void hm2_write_regs(struct hm2_board *b, const struct hm2_module_desc *md,
                    int reg, int n, const u32 *src)
{
    u16 addr;
    int i;
    if (n <= 0)
        return;
    addr = hm2_reg_addr(md, reg);
    if (md->instance_stride == 4) {
        hm2_queue_write(b, addr, src, n);
        return;
    }
    for (i = 0; i < n; i++)
        hm2_queue_write(b, (u16)(addr + i * md->instance_stride), src + i, 1);
}

int hm2_instances(struct hm2_board *b, int gtag, int asked,
                  const char *key, const char *what)
{
    struct hm2_module_desc *md = hm2_find_module(b, gtag);
    int have = md ? md->instances : 0;
    (void)what;
    /* as the reference: a module the firmware lacks takes any count */
    if (md == NULL)
        return 0;
    if (asked < 0)
        asked = have;
    if (asked > have) {
        HM2_ERR(b, "config: %s=%d, but only %d are available", key, asked,
                have);
        return -EINVAL;
    }
    if (asked > HM2_MAX_INST) {
        HM2_ERR(b, "%d %s: this driver supports %d", asked, what,
                HM2_MAX_INST);
        return -EINVAL;
    }
    return asked;
}

static u32 get32(const u8 *p)
{
    return (u32)p[0] | ((u32)p[1] << 8) | ((u32)p[2] << 16)
        | ((u32)p[3] << 24);
}

/* ------------------------------------------------------------ errors */

static long read_timeout_ns(struct hm2_board *b, long period)
{
    long t = b->packet_read_timeout, ns;
    if (t <= 0)
        ns = period / 10 * 8;
    else if (t < 100)
        ns = period / 100 * t;
    else
        ns = t;
    return ns < 100000 ? 100000 : ns;
}

/* once per cycle, after the read: the packet-error pins */
static void account(struct hm2_board *b)
{
    s32 level = *b->packet_error_level, limit = b->packet_error_limit;
    if (b->cycle_error) {
        *b->packet_error_total += 1;
        level += b->packet_error_increment;
        if (level > limit)
            level = limit;
    } else {
        level -= b->packet_error_decrement;
        if (level < 0)
            level = 0;
    }
    *b->packet_error = b->cycle_error != 0;
    *b->packet_error_level = level;
    *b->packet_error_exceeded = level >= limit;
    if (b->cycle_error && level >= limit) {
        b->io_error = 1;
        b->io_error_was = 1;
        HM2_ERR(b, "%s: packet error level %d reached the limit %d: the "
                "board stops (set %s.io_error false to resume)",
                b->link.where, level, limit, b->name);
    }
    b->cycle_error = 0;
}

/* true while the board is stopped by an I/O error; notices the reset */
static int stopped(struct hm2_board *b)
{
    if (b->io_error) {
        b->io_error_was = 1;
        return 1;
    }
    if (b->io_error_was) {
        b->io_error_was = 0;
        *b->packet_error_level = 0;
        *b->packet_error_exceeded = 0;
        *b->packet_error = 0;
        b->read_pending = 0;
        b->force_write = 1;
        b->resync = 1;
        /* the watchdog bit while the board was stopped: resuming is the
           user's reset of it too */
        if (b->wd.present && !*b->wd.has_bit)
            b->wd.was_bit = 1;
        HM2_ERR(b, "io_error reset: resuming");
    }
    return 0;
}

/* ------------------------------------------------------------ functions */

static void send_read_request(struct hm2_board *b)
{
    lbp16_drain(&b->link);          /* late answers of earlier cycles */
    hm2_send(b, &b->rdreq);
    b->read_pending = 1;
}

static void hm2_read_request(void *arg, long period)
{
    struct hm2_board *b = arg;
    (void)period;
    if (stopped(b))
        return;
    send_read_request(b);
}

static void hm2_read(void *arg, long period)
{
    struct hm2_board *b = arg;
    int r, i, off = 0;

    b->period = period;
    if (stopped(b))
        return;
    if (!b->read_pending)
        send_read_request(b);
    b->read_pending = 0;
    r = lbp16_recv(&b->link, b->rdbuf, b->rdreq.reply,
                   read_timeout_ns(b, period));
    if (r < 0) {
        b->cycle_error = 1;
    } else {
        /* the card's count of datagrams received ends the answer: a
           lost write (or request) shows as a difference */
        u16 rx = (u16)(b->rdbuf[r - 2] | (b->rdbuf[r - 1] << 8));
        if (rx != b->tx_count) {
            if (!b->resync)
                b->cycle_error = 1;
            b->tx_count = rx;
        }
        b->resync = 0;
        for (i = 0; i < b->num_regions; i++) {
            struct hm2_region *rg = &b->region[i];
            int k;
            for (k = 0; k < rg->count; k++, off += 4)
                rg->dst[k] = get32(b->rdbuf + off);
        }
        hm2_watchdog_process(b);
        hm2_gpio_process(b);
        hm2_encoder_process(b, period);
        hm2_stepgen_process(b, period);
    }
    account(b);
}

static void hm2_write(void *arg, long period)
{
    struct hm2_board *b = arg;
    b->period = period;
    if (stopped(b))
        return;
    lbp16_pkt_reset(&b->wr);
    hm2_watchdog_prepare(b);
    if (!hm2_watchdog_blocked(b)) {
        hm2_gpio_prepare(b);
        hm2_encoder_prepare(b);
        hm2_stepgen_prepare(b, period);
        hm2_pwmgen_prepare(b);
        hm2_led_prepare(b);
    }
    hm2_send(b, &b->wr);
    b->force_write = 0;
}

/* ------------------------------------------------------------ load */

static void lower(char *dst, const char *src, int len)
{
    int i;
    for (i = 0; i < len - 1 && src[i]; i++)
        dst[i] = (src[i] >= 'A' && src[i] <= 'Z') ? src[i] - 'A' + 'a'
            : src[i];
    dst[i] = 0;
}

static void print_idrom(struct hm2_board *b)
{
    int i;
    rtapi_print("%s: IDROM type %u, %s, %u ports of %u pins, clocks %u/%u "
                "Hz\n", b->name, b->idrom.idrom_type, b->idrom.board_name,
                b->idrom.io_ports, b->idrom.port_width, b->idrom.clock_low,
                b->idrom.clock_high);
    for (i = 0; i < b->num_md; i++)
        rtapi_print("%s: module gtag %d v%d: %d at 0x%04x, %d registers\n",
                    b->name, b->md[i].gtag, b->md[i].version,
                    b->md[i].instances, b->md[i].base_address,
                    b->md[i].num_registers);
    for (i = 0; i < b->num_pins; i++)
        if (b->pin[i].owner_gtag)
            rtapi_print("%s: I/O pin %03d: gtag %d instance %d pin 0x%02x\n",
                        b->name, i, b->pin[i].owner_gtag,
                        b->pin[i].owner_inst, b->pin[i].sec_pin);
}

static int export_board(struct hm2_board *b)
{
    int r;
    r = hal_pin_bit_newf(HAL_OUT, &b->packet_error, comp_id,
                         "%s.packet-error", b->name);
    if (!r)
        r = hal_pin_s32_newf(HAL_OUT, &b->packet_error_level, comp_id,
                             "%s.packet-error-level", b->name);
    if (!r)
        r = hal_pin_bit_newf(HAL_OUT, &b->packet_error_exceeded, comp_id,
                             "%s.packet-error-exceeded", b->name);
    if (!r)
        r = hal_pin_u32_newf(HAL_IO, &b->packet_error_total, comp_id,
                             "%s.packet-error-total", b->name);
    if (!r)
        r = hal_param_bit_newf(HAL_RW, &b->io_error, comp_id, "%s.io_error",
                               b->name);
    if (!r)
        r = hal_param_s32_newf(HAL_RO, &b->packet_error_decrement, comp_id,
                               "%s.packet-error-decrement", b->name);
    if (!r)
        r = hal_param_s32_newf(HAL_RW, &b->packet_error_increment, comp_id,
                               "%s.packet-error-increment", b->name);
    if (!r)
        r = hal_param_s32_newf(HAL_RW, &b->packet_error_limit, comp_id,
                               "%s.packet-error-limit", b->name);
    if (!r)
        r = hal_param_s32_newf(HAL_RW, &b->packet_read_timeout, comp_id,
                               "%s.packet-read-timeout", b->name);
    if (r < 0)
        return r;
    *b->packet_error = 0;
    *b->packet_error_level = 0;
    *b->packet_error_exceeded = 0;
    *b->packet_error_total = 0;
    b->io_error = 0;
    b->packet_error_decrement = 1;
    b->packet_error_increment = 2;
    b->packet_error_limit = 10;
    b->packet_read_timeout = 80;
    r = hal_export_functf(hm2_read, b, 1, 0, comp_id, "%s.read", b->name);
    if (!r)
        r = hal_export_functf(hm2_write, b, 1, 0, comp_id, "%s.write",
                              b->name);
    if (!r)
        r = hal_export_functf(hm2_read_request, b, 1, 0, comp_id,
                              "%s.read-request", b->name);
    return r;
}

static int load_board(struct hm2_board *b, int i)
{
    char raw[32];
    int r, k, same = 0;

    r = lbp16_open(&b->link, board_ip[i]);
    if (r < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "hm2_eth: board_ip '%s': %s\n",
                        board_ip[i], r == -EINVAL
                        ? "not an IPv4 address (a.b.c.d or a.b.c.d:port)"
                        : strerror(-r));
        return r == -EINVAL ? r : -ENODEV;
    }
    r = lbp16_board_name(&b->link, raw, sizeof(raw));
    if (r < 0 || raw[0] == 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "hm2_eth: %s: %s\n", b->link.where,
                        r == -ETIMEDOUT || r == -ECONNREFUSED || r == 0
                        ? "no answer from the card (is it powered and "
                          "connected, and is board_ip right?)"
                        : strerror(-r));
        return -ENODEV;
    }
    lower(b->type, raw, sizeof(b->type));
    for (k = 0; k < num_boards; k++)
        if (boards[k] != b && strcmp(boards[k]->type, b->type) == 0)
            same++;
    b->index = same;
    snprintf(b->name, sizeof(b->name), "hm2_%s.%d", b->type, b->index);

    r = hm2_read_idrom(b);
    if (r < 0) {
        if (r != -ENODEV)
            HM2_ERR(b, "%s: reading the IDROM failed: %s", b->link.where,
                    strerror(-r));
        return -ENODEV;
    }
    r = hm2_parse_config(b->name, config[i], &b->cfg);
    if (r < 0)
        return r;
    if (b->cfg.enable_raw)
        HM2_ERR(b, "config: enable_raw is not supported by this driver; "
                "ignored");
    r = hm2_instances(b, HM2_GTAG_ENCODER, b->cfg.num_encoders,
                      "num_encoders", "encoders");
    if (r < 0)
        return r;
    b->enc.num = r;
    r = hm2_instances(b, HM2_GTAG_STEPGEN, b->cfg.num_stepgens,
                      "num_stepgens", "stepgens");
    if (r < 0)
        return r;
    b->sg.num = r;
    b->sg.width = b->cfg.stepgen_width;
    r = hm2_instances(b, HM2_GTAG_PWMGEN, b->cfg.num_pwmgens,
                      "num_pwmgens", "pwmgens");
    if (r < 0)
        return r;
    b->pwm.num = r;
    hm2_assign_pins(b);
    if (debug)
        print_idrom(b);

    lbp16_pkt_reset(&b->rdreq);
    b->num_regions = 0;
    r = export_board(b);
    if (!r)
        r = hm2_watchdog_setup(b, comp_id);
    if (!r)
        r = hm2_gpio_setup(b, comp_id);
    if (!r)
        r = hm2_encoder_setup(b, comp_id);
    if (!r)
        r = hm2_stepgen_setup(b, comp_id);
    if (!r)
        r = hm2_pwmgen_setup(b, comp_id);
    if (!r)
        r = hm2_led_setup(b, comp_id);
    if (!r)
        r = hm2_pin_aliases(b);
    if (!r && lbp16_pkt_read(&b->rdreq, LBP16_SPACE_COMM, 0, COMM_RX_COUNT,
                             1) < 0) {
        HM2_ERR(b, "too many registers to read in one packet");
        r = -ENOSPC;
    }
    if (r < 0)
        return r;
    /* the modules' set-up goes to the card now, as the reference's does
       at load, so the first cycles are short; the watchdog sleeps until
       the first write function */
    lbp16_pkt_reset(&b->wr);
    b->force_write = 1;
    hm2_gpio_prepare(b);
    hm2_encoder_prepare(b);
    hm2_stepgen_prepare(b, 1000000);
    hm2_pwmgen_prepare(b);
    hm2_led_prepare(b);
    r = lbp16_send(&b->link, &b->wr);
    b->force_write = 0;
    if (!r)
        r = lbp16_rx_count(&b->link, &b->tx_count);
    if (r < 0) {
        HM2_ERR(b, "%s: the set-up of the modules failed: %s",
                b->link.where, strerror(-r));
        return -ENODEV;
    }
    return 0;
}

int rtapi_app_main(void)
{
    int i, r = 0;

    num_boards = 0;
    for (i = 0; i < HM2_MAX_BOARDS; i++)
        boards[i] = NULL;
    if (board_ip[0] == NULL || board_ip[0][0] == 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "hm2_eth: no board_ip given "
                        "(board_ip=a.b.c.d)\n");
        return -EINVAL;
    }
    comp_id = hal_init(HM2_NAME);
    if (comp_id < 0)
        return comp_id;
    for (i = 0; i < HM2_MAX_BOARDS && board_ip[i] && board_ip[i][0]; i++) {
        struct hm2_board *b = hal_malloc(sizeof(*b));
        if (b == NULL) {
            r = -ENOMEM;
            break;
        }
        memset(b, 0, sizeof(*b));
        b->link.fd = -1;
        boards[num_boards++] = b;
        r = load_board(b, i);
        if (r < 0)
            break;
    }
    if (r < 0) {
        for (i = 0; i < num_boards; i++)
            lbp16_close(&boards[i]->link);
        num_boards = 0;
        hal_exit(comp_id);
        return r;
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    int i;
    for (i = 0; i < num_boards; i++) {
        hm2_watchdog_bite_now(boards[i]);
        lbp16_close(&boards[i]->link);
    }
    num_boards = 0;
    hal_exit(comp_id);
}
