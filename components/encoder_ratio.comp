component encoder_ratio """Electronic gear: the position error of a slave axis that must follow
a master axis at a fixed ratio""";

description """
encoder_ratio reads the quadrature encoders of two axes and gives the
position error of the slave axis, in slave revolutions, for a PID loop
that makes the slave follow the master like a pair of gears with
\\fBmaster-teeth\\fR and \\fBslave-teeth\\fR teeth: one master revolution
should turn the slave master-teeth / slave-teeth revolutions.

Both encoders are counted on every edge of A and B (four counts per cycle;
\\fBmaster-ppr\\fR and \\fBslave-ppr\\fR are those counts per revolution).
A leading B counts up.

While \\fBenable\\fR is false only the slave is counted, so \\fBerror\\fR is
the slave position in revolutions: with the PID command at 0 the slave
holds still.  While it is true every master count also moves the target,
and error becomes slave position minus master-teeth / slave-teeth times
master position (counted from when enable went true).  error is 0 while
any of master-ppr, slave-ppr or slave-teeth is 0.

\\fBencoder-ratio.sample\\fR counts; put it in a thread at least twice as
fast as the fastest edge rate.  \\fBencoder-ratio.update\\fR computes error
and can run in the slower servo thread.
""";

notes """
encoder_ratio makes at most 8 channels.  num_chan= and names= cannot be
given together; with neither there is one channel, encoder-ratio.0.
""";

modparam dummy num_chan """Number of axis pairs to make (1 to 8, default 1); they are
named encoder-ratio.0, encoder-ratio.1, ...""";
modparam dummy names """Comma-separated names of the axis pairs to make (at most 8),
instead of num_chan""";

pin in bit master_A "Phase A of the master axis encoder.";
pin in bit master_B "Phase B of the master axis encoder.";
pin in bit slave_A "Phase A of the slave axis encoder.";
pin in bit slave_B "Phase B of the slave axis encoder.";
pin in bit enable "False: error is the slave position; true: the slave must follow the master.";
pin out float error "Position error of the slave, in slave revolutions (feed it to the feedback of a PID loop whose command is 0).";
pin io u32 master_ppr "Counts per revolution of the master encoder (4 per encoder line).";
pin io u32 slave_ppr "Counts per revolution of the slave encoder (4 per encoder line).";
pin io u32 master_teeth "Teeth of the (virtual) master gear.";
pin io u32 slave_teeth "Teeth of the (virtual) slave gear.";

variable int mstate;
variable int sstate;
variable long long acc;

option rtapi_app no;

see_also "encoder(9), pid(9)";
author "the halsdk authors";
license "GPL";
;;
#define MAX_CHAN 8

static int num_chan;
RTAPI_MP_INT(num_chan, "number of axis pairs");
static char *names[MAX_CHAN];
RTAPI_MP_ARRAY_STRING(names, MAX_CHAN, "names of the axis pairs");

/* count change for a quadrature move from state o to n (A | B<<1) */
static const signed char qstep[16] = {
/* n:  00  A   B   AB        o: */
        0, +1, -1,  0,      /* 00 */
       -1,  0,  0, +1,      /* A  */
       +1,  0,  0, -1,      /* B  */
        0, -1, +1,  0,      /* AB */
};

/* the error is kept as an integer in units of
   1 / (slave-ppr * master-ppr * slave-teeth) slave revolutions:
   a slave count is slave-teeth * master-ppr of them, a master count
   master-teeth * slave-ppr */
static void sample(void *arg, long period)
{
    struct __comp_state *__comp_inst;

    FOR_ALL_INSTS() {
        int m = (master_A ? 1 : 0) | (master_B ? 2 : 0);
        int s = (slave_A ? 1 : 0) | (slave_B ? 2 : 0);
        int dm = qstep[(mstate << 2) | m];
        int ds = qstep[(sstate << 2) | s];

        mstate = m;
        sstate = s;
        if (ds)
            acc += (long long)ds * slave_teeth * master_ppr;
        if (dm && enable)
            acc -= (long long)dm * master_teeth * slave_ppr;
    }
}

static void update(void *arg, long period)
{
    struct __comp_state *__comp_inst;

    FOR_ALL_INSTS() {
        double d = (double)slave_ppr * master_ppr * slave_teeth;

        error = d != 0.0 ? acc / d : 0.0;
    }
}

int rtapi_app_main(void)
{
    char buf[HAL_NAME_LEN + 1];
    int n, r;

    if (num_chan && names[0]) {
        rtapi_print_msg(RTAPI_MSG_ERR,
                        "num_chan= and names= are mutually exclusive\n");
        return -EINVAL;
    }
    if (!names[0]) {
        if (!num_chan)
            num_chan = 1;
        if (num_chan < 1 || num_chan > MAX_CHAN) {
            rtapi_print_msg(RTAPI_MSG_ERR,
                            "ENCODER_RATIO: ERROR: invalid number of channels: %d\n",
                            num_chan);
            return -EPERM;
        }
    }

    comp_id = hal_init("encoder_ratio");
    if (comp_id < 0)
        return comp_id;

    if (names[0]) {
        for (n = 0; n < MAX_CHAN && names[n] && names[n][0]; n++) {
            r = export(names[n], n);
            if (r != 0)
                goto fail;
        }
    } else {
        for (n = 0; n < num_chan; n++) {
            rtapi_snprintf(buf, sizeof(buf), "encoder-ratio.%d", n);
            r = export(buf, n);
            if (r != 0)
                goto fail;
        }
    }

    r = hal_export_funct("encoder-ratio.sample", sample, NULL, 0, 0, comp_id);
    if (r != 0)
        goto fail;
    r = hal_export_funct("encoder-ratio.update", update, NULL, 1, 0, comp_id);
    if (r != 0)
        goto fail;

    hal_ready(comp_id);
    return 0;

fail:
    hal_exit(comp_id);
    return r;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
