component mux_generic "Multiplexers of any size from 2 to 1024 inputs, with a choice of input and output types";

description """Each comma-separated entry of the config string makes one multiplexer,
named mux-gen.00, mux-gen.01, ... in order, with its own function of the same
name. An entry holds one or two type letters and a number of inputs, for
example config="bb4,fu12" makes a 4-input bit multiplexer and a 12-input
multiplexer of float inputs with an unsigned (u32) output. The letters are b
(bit), f (float), s (s32) and u (u32), in either case; the first is the type
of the inputs, the second that of the output (with a single letter both have
that type). The digits may stand before, between or after the letters; a
number above 1024 makes 1024 inputs. No spaces are allowed.

The HAL names of multiplexer NN start with mux-gen.NN (the tables below
write mux-generic.N). Besides the pins and parameters listed there, each has:
.TP
\\fBmux-gen.\\fINN\\fB.in-\\fITYPE\\fB-\\fIMM\\fR \\fITYPE\\fR in
The inputs, MM from 00; TYPE is bit, float, s32 or u32.
.TP
\\fBmux-gen.\\fINN\\fB.out-\\fITYPE\\fR \\fITYPE\\fR out
A copy of the selected input, converted to the output type: float to bit is
TRUE for any value other than zero; a float is truncated towards zero and
limited to -2147483647..2147483647 for s32 and to 0..4294967295 for u32; a
negative s32 gives u32 0, and a u32 above 2147483647 gives s32 2147483647.
.PP
The function of a multiplexer that has a float input or output needs a
floating-point thread; the others may run in a base thread.""";

pin in bit suppress-no-input """TRUE: while the selection is 0, keep the output as it is (input 00 cannot
be selected), for switches that open every contact between two positions""";
pin in u32 debounce-us """How long, in microseconds, a new selection must differ from the current
one before the output follows it (e.g. 100000 for 0.1 s); 0 follows at once.
The wait starts afresh whenever the selection returns to the current one""";
pin in bit sel-bit-##[10] """The selection as a binary number, sel-bit-00 the least significant bit.
A multiplexer has one of these for each bit after the first of the largest
power of two not above its size, e.g. 2 for 4 to 7 inputs""";
pin in u32 sel-int """The selection as a number, added to the one on the sel-bit pins; a
selection past the last input selects the last input""";
param r u32 elapsed "How long the pending selection has been waiting, in microseconds";
param r u32 selected "The selection in force: the number of the input copied to the output, or a number past the last input, which copies the last one";

modparam dummy config """The multiplexers to make: a comma-separated list of entries like bb4 or
fu12 (type of the inputs, type of the output, number of inputs); at most 100
entries""";

option rtapi_app no;

see_also "mux2(9), mux4(9), mux8(9), mux16(9), demux(9)";
author "the halsdk authors";
license "GPL";
;;
#define MAX_MUX 100
#define MAX_SIZE 1024
#define MAX_BITS 10

static char *config[MAX_MUX];
RTAPI_MP_ARRAY_STRING(config, MAX_MUX, "multiplexers to make, e.g. bb4,fu12");

enum { T_BIT, T_FLOAT, T_S32, T_U32 };

static const char *type_name[] = {"bit", "float", "s32", "u32"};

typedef union {
    hal_bit_t *b;
    hal_float_t *f;
    hal_s32_t *s;
    hal_u32_t *u;
} any_pin;

typedef struct {
    hal_bit_t *suppress;
    hal_u32_t *debounce;
    hal_u32_t *sel_num;
    hal_bit_t *sel[MAX_BITS];
    any_pin out;
    any_pin *in;                /* size pointers, from hal_malloc */
    hal_u32_t waited;           /* the params elapsed and selected */
    hal_u32_t chosen;
    int nbits;
    int size;
    int in_type;
    int out_type;
} mux_t;

/* Parse one config entry into its types and size; 0, or -1 with a
   message in the reference's words. */
static int parse_entry(const char *e, int *in_type, int *out_type, int *size)
{
    int types = 0, n = 0;
    const char *c;

    for (c = e; *c; c++) {
        int t;

        switch (*c) {
        case 'b': case 'B': t = T_BIT; break;
        case 'f': case 'F': t = T_FLOAT; break;
        case 's': case 'S': t = T_S32; break;
        case 'u': case 'U': t = T_U32; break;
        default:
            if (*c >= '0' && *c <= '9') {
                if (n <= MAX_SIZE)      /* stop growing, no overflow */
                    n = n * 10 + (*c - '0');
                continue;
            }
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "mux_generic: invalid character in fmt string\n");
            return -1;
        }
        if (types == 0) {
            *in_type = *out_type = t;
        } else if (types == 1) {
            *out_type = t;
        } else {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "mux_generic: too many type specifiers in fmt string\n");
            return -1;
        }
        types++;
    }
    if (n == 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "mux_generic: No entry count given\n");
        return -1;
    }
    if (n == 1) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "mux_generic: A one-element mux makes no sense\n");
        return -1;
    }
    if (types == 0) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "mux_generic: No type specifiers in fmt string\n");
        return -1;
    }
    *size = n > MAX_SIZE ? MAX_SIZE : n;
    return 0;
}

static void update(void *arg, long period)
{
    mux_t *m = arg;
    rtapi_u32 s = *m->sel_num;
    int i;

    for (i = 0; i < m->nbits; i++)
        s += (rtapi_u32)*m->sel[i] << i;

    /* all contacts of a switch open between two positions: hold */
    if (*m->suppress && s == 0)
        return;

    /* a new selection waits for the debounce time; the time starts
       afresh whenever the selection is back to the current one.  As in
       the reference, the selection compared (and shown by the selected
       param) is the number asked for, before a number past the last input
       is turned into the last input: moving from 9 to 10 on 8 inputs
       waits too */
    if (s != m->chosen) {
        if (m->waited < *m->debounce) {
            m->waited += period / 1000;
            return;
        }
        m->chosen = s;
    }
    m->waited = 0;
    if (s >= (rtapi_u32)m->size)
        s = m->size - 1;

    if (m->in_type == T_FLOAT) {
        double v = *m->in[s].f;

        switch (m->out_type) {
        case T_BIT:
            *m->out.b = v != 0;
            break;
        case T_FLOAT:
            *m->out.f = v;
            break;
        case T_S32:
            if (v > 2147483647.0)
                v = 2147483647.0;
            else if (v < -2147483647.0)
                v = -2147483647.0;
            *m->out.s = (hal_s32_t)v;
            break;
        default:
            if (v > 4294967295.0)
                v = 4294967295.0;
            else if (v < 0)
                v = 0;
            *m->out.u = (hal_u32_t)v;
            break;
        }
        return;
    }

    /* integer and bit inputs: go through a 64-bit value */
    {
        rtapi_s64 v;

        if (m->in_type == T_BIT)
            v = *m->in[s].b;
        else if (m->in_type == T_S32)
            v = *m->in[s].s;
        else
            v = *m->in[s].u;
        switch (m->out_type) {
        case T_BIT:
            *m->out.b = v != 0;
            break;
        case T_FLOAT:
            *m->out.f = (double)v;
            break;
        case T_S32:
            *m->out.s = v > 2147483647 ? 2147483647 : (hal_s32_t)v;
            break;
        default:
            *m->out.u = v < 0 ? 0 : (hal_u32_t)v;
            break;
        }
    }
}

static int new_pin(int type, hal_pin_dir_t dir, any_pin *p, const char *name)
{
    switch (type) {
    case T_BIT:
        return hal_pin_bit_newf(dir, &p->b, comp_id, "%s", name);
    case T_FLOAT:
        return hal_pin_float_newf(dir, &p->f, comp_id, "%s", name);
    case T_S32:
        return hal_pin_s32_newf(dir, &p->s, comp_id, "%s", name);
    default:
        return hal_pin_u32_newf(dir, &p->u, comp_id, "%s", name);
    }
}

static int make_mux(int k, int in_type, int out_type, int size)
{
    char pre[HAL_NAME_LEN + 1], name[HAL_NAME_LEN + 1];
    mux_t *m = hal_malloc(sizeof(mux_t));
    int i, r;

    if (!m)
        return -ENOMEM;
    m->in = hal_malloc(size * sizeof(any_pin));
    if (!m->in)
        return -ENOMEM;
    m->size = size;
    m->in_type = in_type;
    m->out_type = out_type;
    m->waited = 0;
    m->chosen = 0;
    /* one selection bit per binary digit below the top one */
    for (m->nbits = 0; (2 << m->nbits) <= size; m->nbits++)
        ;

    rtapi_snprintf(pre, sizeof(pre), "mux-gen.%02d", k);
    r = hal_pin_bit_newf(HAL_IN, &m->suppress, comp_id,
                         "%s.suppress-no-input", pre);
    if (r == 0)
        r = hal_pin_u32_newf(HAL_IN, &m->debounce, comp_id,
                             "%s.debounce-us", pre);
    if (r == 0)
        r = hal_pin_u32_newf(HAL_IN, &m->sel_num, comp_id, "%s.sel-int", pre);
    for (i = 0; r == 0 && i < m->nbits; i++)
        r = hal_pin_bit_newf(HAL_IN, &m->sel[i], comp_id,
                             "%s.sel-bit-%02d", pre, i);
    for (i = 0; r == 0 && i < size; i++) {
        rtapi_snprintf(name, sizeof(name), "%s.in-%s-%02d", pre,
                       type_name[in_type], i);
        r = new_pin(in_type, HAL_IN, &m->in[i], name);
    }
    if (r == 0) {
        rtapi_snprintf(name, sizeof(name), "%s.out-%s", pre,
                       type_name[out_type]);
        r = new_pin(out_type, HAL_OUT, &m->out, name);
    }
    if (r == 0)
        r = hal_param_u32_newf(HAL_RO, &m->waited, comp_id,
                               "%s.elapsed", pre);
    if (r == 0)
        r = hal_param_u32_newf(HAL_RO, &m->chosen, comp_id,
                               "%s.selected", pre);
    if (r == 0)
        r = hal_export_funct(pre, update, m,
                             in_type == T_FLOAT || out_type == T_FLOAT,
                             0, comp_id);
    return r;
}

int rtapi_app_main(void)
{
    int in_type[MAX_MUX], out_type[MAX_MUX], size[MAX_MUX];
    int k, n, r = 0;

    if (!config[0]) {
        rtapi_print_msg(RTAPI_MSG_ERR, "The mux_generic component requires "
                        "at least one valid format string\n");
        return -EINVAL;
    }
    /* check every entry before making anything */
    for (n = 0; n < MAX_MUX && config[n]; n++)
        if (parse_entry(config[n], &in_type[n], &out_type[n], &size[n]))
            return -EPERM;

    comp_id = hal_init("mux_generic");
    if (comp_id < 0)
        return comp_id;
    for (k = 0; k < n && r == 0; k++)
        r = make_mux(k, in_type[k], out_type[k], size[k]);
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
