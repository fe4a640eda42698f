component weighted_sum "Turn a group of bits into an integer: the sum of the weights of the TRUE bits";

pin out s32 sum "(wsum.N.sum) offset + the weights of the TRUE bits; see the description for all pins";

option rtapi_app no;

description """
\\fBloadrt weighted_sum wsum_sizes=\\fIsize\\fR[,\\fIsize\\fR...]

Makes up to 8 summers \\fBwsum.0\\fR, \\fBwsum.1\\fR, ..., one for each size
given, each with that many input bits (at least 1).  With the default
weights a summer converts a binary number to an integer; other weights give
BCD, Gray-like or any other codes.  The weights and the offset are io pins
(set them with setp).  One function, \\fBprocess_wsums\\fR, updates every
summer.  A size of -1 ends the list.

Pins of summer N: \\fBwsum.N.bit.M.in\\fR (bit in), input M;
\\fBwsum.N.bit.M.weight\\fR (s32 io), its weight, 2^M by default (0 from
bit 32 on); \\fBwsum.N.hold\\fR (bit in), while TRUE the sum keeps its
value; \\fBwsum.N.offset\\fR (s32 io), added to the weights of the TRUE
bits; \\fBwsum.N.sum\\fR (s32 out), the result, wrapping around on overflow.
""";
see_also "scaled_s32_sums(9), sum2(9)";
author "the halsdk authors";
license "GPL";
;;
#define MAX_SUMMERS 8

typedef struct {
    hal_bit_t *p_in;
    hal_s32_t *p_weight;
} wbit_t;

typedef struct {
    hal_bit_t *p_hold;
    hal_s32_t *p_offset;
    hal_s32_t *p_sum;
    int p_nbits;
    wbit_t *p_bits;
} summer_t;

static int wsum_sizes[MAX_SUMMERS] = {-1, -1, -1, -1, -1, -1, -1, -1};
RTAPI_MP_ARRAY_INT(wsum_sizes, MAX_SUMMERS, "Input bits of each summer (up to 8 summers)");

static summer_t *summers;
static int nsummers;

static void process_wsums(void *arg, long period)
{
    int i, b;

    (void)arg;
    (void)period;
    for (i = 0; i < nsummers; i++) {
        summer_t *s = &summers[i];
        rtapi_u32 acc;

        if (*s->p_hold)
            continue;
        /* unsigned, so that an overflowing sum wraps around */
        acc = (rtapi_u32)*s->p_offset;
        for (b = 0; b < s->p_nbits; b++)
            if (*s->p_bits[b].p_in)
                acc += (rtapi_u32)*s->p_bits[b].p_weight;
        *s->p_sum = (rtapi_s32)acc;
    }
}

static int export_summer(int n, summer_t *s)
{
    rtapi_u32 w = 1;
    int b, r;

    r = hal_pin_s32_newf(HAL_IO, &s->p_offset, comp_id, "wsum.%d.offset", n);
    if (r == 0)
        r = hal_pin_s32_newf(HAL_OUT, &s->p_sum, comp_id, "wsum.%d.sum", n);
    if (r == 0)
        r = hal_pin_bit_newf(HAL_IN, &s->p_hold, comp_id, "wsum.%d.hold", n);
    for (b = 0; r == 0 && b < s->p_nbits; b++) {
        r = hal_pin_bit_newf(HAL_IN, &s->p_bits[b].p_in, comp_id,
                             "wsum.%d.bit.%d.in", n, b);
        if (r == 0)
            r = hal_pin_s32_newf(HAL_IO, &s->p_bits[b].p_weight, comp_id,
                                 "wsum.%d.bit.%d.weight", n, b);
        if (r == 0)
            *s->p_bits[b].p_weight = (rtapi_s32)w;
        w <<= 1;        /* 0 once past bit 31 */
    }
    if (r == 0) {
        *s->p_offset = 0;
        *s->p_sum = 0;
        *s->p_hold = 0;
    }
    return r;
}

int rtapi_app_main(void)
{
    int i, r;

    /* the sizes up to the first -1 */
    for (nsummers = 0; nsummers < MAX_SUMMERS; nsummers++) {
        int n = wsum_sizes[nsummers];
        if (n == -1)
            break;
        if (n < 1) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "WEIGHTED_SUM: ERROR: Invalid number of bits '%i' for summer %i\n",
                            n, nsummers);
            return -EPERM;
        }
    }
    if (nsummers == 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "WEIGHTED_SUM: ERROR: no summers specified\n");
        return -EPERM;
    }
    comp_id = hal_init("weighted_sum");
    if (comp_id < 0)
        return comp_id;
    summers = hal_malloc(nsummers * sizeof(summer_t));
    if (!summers) {
        hal_exit(comp_id);
        return -ENOMEM;
    }
    for (i = 0; i < nsummers; i++) {
        summers[i].p_nbits = wsum_sizes[i];
        summers[i].p_bits = hal_malloc(wsum_sizes[i] * sizeof(wbit_t));
        if (!summers[i].p_bits) {
            hal_exit(comp_id);
            return -ENOMEM;
        }
        r = export_summer(i, &summers[i]);
        if (r != 0) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "WEIGHTED_SUM: ERROR: summer %d export failed\n", i);
            hal_exit(comp_id);
            return r;
        }
    }
    r = hal_export_funct("process_wsums", process_wsums, NULL, 1, 0, comp_id);
    if (r != 0) {
        hal_exit(comp_id);
        return r;
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
