/*
 * hm2.h - the realtime driver of Mesa HostMot2 cards over Ethernet.
 *
 * One board is a struct hm2_board allocated with hal_malloc.  At load
 * time the driver reads the card's IDROM (module and pin descriptors),
 * parses the config string, creates the HAL objects of each module it
 * supports and builds, once, the commands of the realtime exchanges.
 * In the thread, read/write/read_request do one UDP exchange each over
 * a socket opened at load time: no allocation, no locks, a bounded wait.
 *
 * Files, one job each:
 *   lbp16.c     the LBP16 protocol: socket, packets, bounded exchange
 *   idrom.c     reading and checking the IDROM
 *   config.c    the config string (num_encoders=..., sserial_port_0=...)
 *   pins.c      assignment of I/O pins to module instances, aliases
 *   gpio.c      the IOPort module (GPIO)
 *   watchdog.c  the watchdog
 *   encoder.c   quadrature encoders
 *   stepgen.c   step generators and their position/velocity loop
 *   pwmgen.c    PWM generators
 *   led.c       the board's LEDs
 *   hm2_eth.c   the module: modparams, load, the thread functions and
 *               the packet-error accounting
 */
#ifndef HM2_H
#define HM2_H

#include "rtapi.h"
#include "hal.h"

typedef unsigned char u8;
typedef unsigned short u16;
typedef unsigned int u32;
typedef int s32;

#define HM2_NAME "hm2_eth"
#define HM2_MAX_BOARDS 4
#define HM2_MAX_MODULES 48
#define HM2_MAX_PINS 256
#define HM2_MAX_INST 32
#define HM2_PORT 27181

/* ------------------------------------------------------------ LBP16 */

#define LBP16_WRITE 0x8000
#define LBP16_ADDR 0x4000
#define LBP16_SPACE(n) ((n) << 10)
#define LBP16_SIZE_16 0x0100
#define LBP16_SIZE_32 0x0200
#define LBP16_INC 0x0080
#define LBP16_COUNT_MAX 127
#define LBP16_SPACE_HM2 0
#define LBP16_SPACE_COMM 6
#define LBP16_SPACE_INFO 7
#define COMM_RX_COUNT 0x0008    /* status space: UDP datagrams received */

#define HM2_PKT_MAX 1400        /* bytes of one UDP packet we build */

/* one packet being built: commands (and data for writes) */
struct lbp16_pkt {
    u8 buf[HM2_PKT_MAX];
    int len;                    /* bytes in buf */
    int reply;                  /* bytes the card answers (reads) */
    int full;                   /* a command did not fit */
};

/* a block of consecutive 32-bit registers read each cycle into dst */
struct hm2_region {
    u16 addr;
    u16 count;
    u32 *dst;
};

#define HM2_MAX_REGIONS 64

struct lbp16_link {
    int fd;                     /* UDP socket, connected, non-blocking */
    char where[64];             /* "ip:port" for messages */
};

/* ------------------------------------------------------------ IDROM */

#define HM2_COOKIE 0x55AACAFE
#define HM2_ADDR_COOKIE 0x0100
#define HM2_ADDR_CONFIGNAME 0x0104
#define HM2_ADDR_IDROM_OFFSET 0x010C

#define HM2_GTAG_WATCHDOG 2
#define HM2_GTAG_IOPORT 3
#define HM2_GTAG_ENCODER 4
#define HM2_GTAG_STEPGEN 5
#define HM2_GTAG_PWMGEN 6
#define HM2_GTAG_LED 128

struct hm2_idrom {
    u32 idrom_type;
    u32 offset_to_modules;
    u32 offset_to_pin_desc;
    char board_name[9];
    u32 fpga_size;
    u32 fpga_pins;
    u32 io_ports;
    u32 io_width;
    u32 port_width;
    u32 clock_low;
    u32 clock_high;
    u32 instance_stride_0;
    u32 instance_stride_1;
    u32 register_stride_0;
    u32 register_stride_1;
};

struct hm2_module_desc {
    u8 gtag;
    u8 version;
    u8 clock_tag;
    u8 instances;
    u16 base_address;
    u8 num_registers;
    u8 strides;
    u32 multiple_registers;
    /* derived */
    u32 clock_hz;
    u32 register_stride;
    u32 instance_stride;
};

struct hm2_pin {
    u8 sec_pin;                 /* bit 7: the module drives it */
    u8 sec_tag;                 /* gtag of the module that may use it */
    u8 sec_unit;                /* instance of that module */
    u8 primary_tag;
    int owner_gtag;             /* 0: plain GPIO */
    int owner_inst;
};

/* ------------------------------------------------------------ config */

struct hm2_config {
    int num_encoders;           /* -1: all the firmware has */
    int num_stepgens;
    int num_pwmgens;
    int num_leds;
    int stepgen_width;
    int enable_raw;
};

/* ------------------------------------------------------------ modules */

struct hm2_gpio_hal {
    hal_bit_t *in;
    hal_bit_t *in_not;
    hal_bit_t *out;             /* NULL for a pin a module uses */
    hal_bit_t is_output;
    hal_bit_t is_opendrain;
    hal_bit_t invert_output;
};

struct hm2_ioport {
    struct hm2_module_desc *md;
    int num_ports;
    int width;                  /* pins per port */
    u16 data_addr, ddr_addr, alt_addr, od_addr, inv_addr;
    u32 read[HM2_MAX_INST];     /* data, read each cycle */
    u32 data[HM2_MAX_INST];     /* output data written each cycle */
    u32 ddr[HM2_MAX_INST];
    u32 alt[HM2_MAX_INST];
    u32 od[HM2_MAX_INST];
    u32 inv[HM2_MAX_INST];
    u32 module_out[HM2_MAX_INST];   /* pins a module drives */
    u32 written_ddr[HM2_MAX_INST], written_od[HM2_MAX_INST],
        written_inv[HM2_MAX_INST];
    struct hm2_gpio_hal *pin;   /* io_width entries */
};

struct hm2_watchdog {
    struct hm2_module_desc *md;
    int present;
    u16 timer_addr, status_addr, reset_addr;
    u32 status;                 /* read each cycle */
    hal_bit_t *has_bit;
    hal_u32_t timeout_ns;
    u32 written_timeout;
    int enabled;                /* the timer was written once */
    int was_bit;
};

struct hm2_encoder_inst {
    hal_s32_t *count, *rawcounts, *count_latched, *rawlatch;
    hal_float_t *position, *velocity, *velocity_rpm;
    hal_float_t *position_latched;
    hal_bit_t *reset, *index_enable, *latch_enable, *latch_polarity;
    hal_bit_t *input_a, *input_b, *input_index;
    hal_bit_t *quad_error, *quad_error_enable;
    hal_float_t scale;
    hal_bit_t index_invert, index_mask, index_mask_invert;
    hal_bit_t counter_mode, filter;
    hal_float_t vel_timeout;
    long long total;            /* extended count */
    long long zero;             /* total at the last reset or index */
    u16 last;
    int primed;
    int index_armed;            /* latch-on-index written to the card */
    double age;                 /* timestamp ticks since the last count */
    u32 ctrl_written;
};

struct hm2_encoder {
    struct hm2_module_desc *md;
    int num;
    u16 counter_addr, latch_addr, tsdiv_addr, tscount_addr, rate_addr;
    u32 counter[HM2_MAX_INST];  /* read */
    u32 latch[HM2_MAX_INST];    /* read: control and latched count */
    u32 ctrl[HM2_MAX_INST];     /* to write */
    int ctrl_dirty[HM2_MAX_INST];
    u32 clock_hz;
    hal_bit_t *hires_timestamp;
    hal_u32_t *sample_frequency;
    u32 w_rate, w_tsdiv;
    u32 tscount;                /* read: the timestamp counter now */
    u16 last_tscount;
    int ts_primed;
    struct hm2_encoder_inst *inst;
};

struct hm2_stepgen_inst {
    hal_float_t *position_cmd, *velocity_cmd;
    hal_s32_t *counts;
    hal_float_t *position_fb, *velocity_fb;
    hal_bit_t *enable, *control_type, *position_reset;
    hal_float_t position_scale, maxvel, maxaccel;
    hal_u32_t steplen, stepspace, dirsetup, dirhold, step_type;
    hal_u32_t table_data[4];
    hal_float_t *dbg_ff_vel, *dbg_vel_error, *dbg_s_to_match,
        *dbg_err_at_match, *dbg_pos_minus_prev_cmd;
    hal_s32_t *dbg_step_rate;
    /* state */
    long long total_counts;     /* extended step count (16.16 in acc) */
    long long zero;             /* subtracted: position-reset */
    u32 last_acc;
    int primed;
    double old_pos_cmd;
    double cur_vel;             /* commanded velocity, units/s */
    double fb_pos;
    u32 w_steplen, w_stepspace, w_dirsetup, w_dirhold, w_mode, w_width;
    int timing_written;
    u32 w_table[4];             /* table-data as last written */
    u32 w_table_len;            /* entries last written (0: none) */
};

struct hm2_stepgen {
    struct hm2_module_desc *md;
    int num;
    int width;                  /* stepgen_width: pins per instance */
    u16 rate_addr, accum_addr, mode_addr, dirsetup_addr, dirhold_addr,
        steplen_addr, stepspace_addr, tablewidth_addr;
    u32 clock_hz;
    u32 accum[HM2_MAX_INST];    /* read */
    u32 rate[HM2_MAX_INST];     /* written each cycle */
    struct hm2_stepgen_inst *inst;
};

struct hm2_pwmgen_inst {
    hal_float_t *value;
    hal_bit_t *enable;
    hal_float_t scale;
    hal_s32_t output_type;
    hal_bit_t offset_mode;
};

struct hm2_pwmgen {
    struct hm2_module_desc *md;
    int num;
    u16 value_addr, mode_addr, pwm_rate_addr, pdm_rate_addr, enable_addr;
    u32 clock_hz;
    u32 value[HM2_MAX_INST];
    u32 mode[HM2_MAX_INST], w_mode[HM2_MAX_INST];
    hal_u32_t pwm_frequency, pdm_frequency;
    u32 w_pwm_freq, w_pdm_freq;
    u32 enable_reg, w_enable_reg;
    int written;
    struct hm2_pwmgen_inst *inst;
};

struct hm2_led {
    struct hm2_module_desc *md;
    int num;
    u16 addr;
    u32 w_reg;
    int written;
    hal_bit_t **pin;            /* num entries */
};

/* ------------------------------------------------------------ board */

struct hm2_board {
    int index;                  /* board number of its type */
    char name[48];              /* "hm2_7i96s.0" */
    char type[32];              /* "7i96s" */
    struct lbp16_link link;
    struct hm2_idrom idrom;
    struct hm2_module_desc md[HM2_MAX_MODULES];
    int num_md;
    struct hm2_pin pin[HM2_MAX_PINS];
    int num_pins;
    struct hm2_config cfg;

    struct hm2_ioport ioport;
    struct hm2_watchdog wd;
    struct hm2_encoder enc;
    struct hm2_stepgen sg;
    struct hm2_pwmgen pwm;
    struct hm2_led led;

    /* the per-cycle read: regions, request built once */
    struct hm2_region region[HM2_MAX_REGIONS];
    int num_regions;
    struct lbp16_pkt rdreq;
    u8 rdbuf[HM2_PKT_MAX];
    struct lbp16_pkt wr;        /* rebuilt each write */
    int read_pending;           /* read_request sent, reply not taken */
    int resync;                 /* take the card's count as it is */
    u16 tx_count;               /* datagrams sent, as the card counts them
                                   (LBP16 status space, COMM_RX_COUNT) */
    int force_write;            /* rewrite every setting: after load,
                                   a watchdog bite, a reconnection */

    /* packet errors (hm2_eth(9)) */
    hal_bit_t *packet_error;
    hal_s32_t *packet_error_level;
    hal_bit_t *packet_error_exceeded;
    hal_u32_t *packet_error_total;
    hal_bit_t io_error;                 /* a param, as the reference's */
    hal_s32_t packet_error_decrement;
    hal_s32_t packet_error_increment;
    hal_s32_t packet_error_limit;
    hal_s32_t packet_read_timeout;
    int cycle_error;
    int io_error_was;
    int io_error_reported;
    long period;                /* ns, the thread's */

    /* raw mode (enable_raw) */
    hal_u32_t *raw_read_address, *raw_read_data;
    hal_u32_t *raw_write_address, *raw_write_data;
    hal_bit_t *raw_write_strobe, *raw_dump_state;
};

/* lbp16.c */
int lbp16_open(struct lbp16_link *l, const char *board_ip);
void lbp16_close(struct lbp16_link *l);
void lbp16_pkt_reset(struct lbp16_pkt *p);
int lbp16_rx_count(struct lbp16_link *l, u16 *count);
int lbp16_pkt_read(struct lbp16_pkt *p, int space, int size32, u16 addr,
                   int count);
int lbp16_pkt_write32(struct lbp16_pkt *p, u16 addr, const u32 *data,
                      int count);
int lbp16_send(struct lbp16_link *l, const struct lbp16_pkt *p);
void lbp16_drain(struct lbp16_link *l);
int lbp16_recv(struct lbp16_link *l, u8 *buf, int want, long timeout_ns);
int lbp16_transact(struct lbp16_link *l, const struct lbp16_pkt *p, u8 *buf,
                   long timeout_ns, int tries);
int lbp16_read32(struct lbp16_link *l, u16 addr, u32 *dst, int count);
int lbp16_write32(struct lbp16_link *l, u16 addr, const u32 *src,
                  int count);
int lbp16_board_name(struct lbp16_link *l, char *name, int len);

/* idrom.c */
int hm2_read_idrom(struct hm2_board *b);
struct hm2_module_desc *hm2_find_module(struct hm2_board *b, int gtag);
u16 hm2_reg_addr(const struct hm2_module_desc *md, int reg);

/* config.c */
int hm2_parse_config(const char *board, const char *text,
                     struct hm2_config *cfg);

/* pins.c */
int hm2_assign_pins(struct hm2_board *b);
int hm2_pin_aliases(struct hm2_board *b);

/* board helpers (hm2_eth.c) */
void hm2_send(struct hm2_board *b, const struct lbp16_pkt *p);
int hm2_add_region(struct hm2_board *b, u16 addr, int count, u32 *dst);
void hm2_queue_write(struct hm2_board *b, u16 addr, const u32 *data,
                     int count);
/* register reg of instances 0..n-1 of a module, whatever its stride */
int hm2_read_regs(struct hm2_board *b, const struct hm2_module_desc *md,
                  int reg, int n, u32 *dst);
void hm2_write_regs(struct hm2_board *b, const struct hm2_module_desc *md,
                    int reg, int n, const u32 *src);
/* the instance count to use: the config's (-1: all), checked against the
   firmware's; a negative errno when more are asked than exist */
int hm2_instances(struct hm2_board *b, int gtag, int asked,
                  const char *key, const char *what);

/* modules: setup at load, process after a read, prepare before a write */
int hm2_gpio_setup(struct hm2_board *b, int comp_id);
void hm2_gpio_process(struct hm2_board *b);
void hm2_gpio_prepare(struct hm2_board *b);

int hm2_watchdog_setup(struct hm2_board *b, int comp_id);
void hm2_watchdog_process(struct hm2_board *b);
void hm2_watchdog_prepare(struct hm2_board *b);
int hm2_watchdog_blocked(struct hm2_board *b);
void hm2_watchdog_bite_now(struct hm2_board *b);

int hm2_encoder_setup(struct hm2_board *b, int comp_id);
void hm2_encoder_process(struct hm2_board *b, long period);
void hm2_encoder_prepare(struct hm2_board *b);

int hm2_stepgen_setup(struct hm2_board *b, int comp_id);
void hm2_stepgen_process(struct hm2_board *b, long period);
void hm2_stepgen_prepare(struct hm2_board *b, long period);

int hm2_pwmgen_setup(struct hm2_board *b, int comp_id);
void hm2_pwmgen_prepare(struct hm2_board *b);

int hm2_led_setup(struct hm2_board *b, int comp_id);
void hm2_led_prepare(struct hm2_board *b);

#define HM2_ERR(b, fmt, ...) \
    rtapi_print_msg(RTAPI_MSG_ERR, "%s: " fmt "\n", (b)->name, ##__VA_ARGS__)

#endif /* HM2_H */
