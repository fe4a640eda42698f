component debounce "Filter noisy digital inputs, in groups that share a delay";

description """
Each filter keeps a counter that goes up by one each period its input is
TRUE and down by one each period it is FALSE, and stays between 0 and the
group's \\fBdelay\\fR.  When the counter already stands at \\fBdelay\\fR and
the input is still TRUE, the output becomes TRUE; when it already stands at
0 and the input is still FALSE, the output becomes FALSE.  In between the
output keeps its state.  So a clean change of an input shows on its output
\\fBdelay\\fR periods later, a delay of 0 copies the inputs at once, and a
pulse shorter than the delay never gets through.

The filters are made in groups: \\fBcfg=\\fR lists the number of filters of
each group (1 to 50; up to 8 groups; a 0 ends the list).  For example
\\fBcfg=2,3\\fR makes group 0 with 2 filters and group 1 with 3.  All filters
of a group share its \\fBdelay\\fR and its function, so they are sampled at
the same rate.  Loading without any group is refused.

.TP
\\fBdebounce.\\fIG\\fB\\fR (function, no floating point)
Samples every input of group \\fIG\\fR and updates its outputs.
.TP
\\fBdebounce.\\fIG\\fB.\\fIF\\fB.in\\fR bit in
Input of filter \\fIF\\fR of group \\fIG\\fR.
.TP
\\fBdebounce.\\fIG\\fB.\\fIF\\fB.out\\fR bit out
The filtered input: its last state that lasted long enough.
.TP
\\fBdebounce.\\fIG\\fB.delay\\fR s32 rw (default: 5)
Number of periods a change must last in group \\fIG\\fR.  A negative value
is replaced by 1 the next time the group's function runs.
""";

notes """
\\fBdbounce\\fR(9) is the same filter with the usual \\fBcount=\\fR and
\\fBnames=\\fR load parameters and a delay pin for each instance.
""";

pin in bit in "(debounce.G.F.in) Input of filter F of group G; see the description for all pins";

modparam dummy cfg "Group sizes, for example cfg=2,3: group 0 with 2 filters and group 1 with 3";

option rtapi_app no;

see_also "dbounce(9), toggle(9)";
author "the halsdk authors";
license "GPL";
;;
#define MAX_GROUPS 8
#define MAX_FILTERS 50

static int cfg[MAX_GROUPS];
RTAPI_MP_ARRAY_INT(cfg, MAX_GROUPS, "group sizes");

struct filter {
    hal_bit_t *p_in;
    hal_bit_t *p_out;
    hal_s32_t count;
};

struct group {
    hal_s32_t delay;
    int size;
    struct filter *filters;
};

static struct group *groups;

static void update(void *arg, long period)
{
    struct group *g = arg;
    int i;

    (void)period;
    /* a negative delay would never let an output change */
    if (g->delay < 0)
        g->delay = 1;
    for (i = 0; i < g->size; i++) {
        struct filter *f = &g->filters[i];
        if (*f->p_in) {
            if (f->count < g->delay)
                f->count++;
            else
                *f->p_out = 1;
        } else {
            if (f->count > 0)
                f->count--;
            else
                *f->p_out = 0;
        }
    }
}

static int make_group(int n, struct group *g)
{
    char name[HAL_NAME_LEN + 1];
    int i, r;

    g->filters = hal_malloc(g->size * sizeof(struct filter));
    if (!g->filters)
        return -ENOMEM;
    for (i = 0; i < g->size; i++) {
        struct filter *f = &g->filters[i];
        r = hal_pin_bit_newf(HAL_IN, &f->p_in, comp_id, "debounce.%d.%d.in",
                             n, i);
        if (r != 0)
            return r;
        r = hal_pin_bit_newf(HAL_OUT, &f->p_out, comp_id,
                             "debounce.%d.%d.out", n, i);
        if (r != 0)
            return r;
        *f->p_in = 0;
        *f->p_out = 0;
        f->count = 0;
    }
    r = hal_param_s32_newf(HAL_RW, &g->delay, comp_id, "debounce.%d.delay",
                           n);
    if (r != 0)
        return r;
    g->delay = 5;
    rtapi_snprintf(name, sizeof(name), "debounce.%d", n);
    return hal_export_funct(name, update, g, 0, 0, comp_id);
}

int rtapi_app_main(void)
{
    int n, i, r;

    /* the groups end at the first size of 0 */
    for (n = 0; n < MAX_GROUPS && cfg[n] != 0; n++) {
        if (cfg[n] < 0 || cfg[n] > MAX_FILTERS) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "DEBOUNCE: ERROR: bad group size '%d'\n",
                            cfg[n]);
            return -1;
        }
    }
    if (n == 0) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "DEBOUNCE: ERROR: no channels configured\n");
        return -1;
    }

    comp_id = hal_init("debounce");
    if (comp_id < 0)
        return comp_id;
    groups = hal_malloc(n * sizeof(struct group));
    if (!groups) {
        hal_exit(comp_id);
        return -ENOMEM;
    }
    for (i = 0; i < n; i++) {
        groups[i].size = cfg[i];
        r = make_group(i, &groups[i]);
        if (r != 0) {
            hal_exit(comp_id);
            return r;
        }
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
