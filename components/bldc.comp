component bldc "Commutation of three-phase brushless motors (BLDC and AC servo) from Hall, encoder or Fanuc feedback";

description """
Works out the position of the rotor of a three-phase permanent magnet motor
from its feedback (Hall sensors, an absolute or incremental encoder, or the
4-bit Gray code of a Fanuc "Red Cap" motor; or none at all) and drives the
three phases to match, in one of several forms of output for the drive.

Each instance is described by a word of letters in \\fBcfg=\\fR, the
instances separated by commas, e.g. \\fBloadrt bldc cfg=qi6,aH\\fR (at most
8 instances; there is no \\fBcount=\\fR or \\fBnames=\\fR).  Letters it
does not know are ignored; without \\fBcfg=\\fR no instance is made.

Feedback letters (lower case):
.TP
\\fBn\\fR
No feedback: the field turns at \\fBfrequency\\fR, e.g. for an induction
motor or a free-running motor simulator.
.TP
\\fBh\\fR
Three Hall sensors (\\fBhall1\\fR..\\fBhall3\\fR), decoded with the
commutation table \\fBpattern\\fR.
.TP
\\fBa\\fR
Absolute encoder on \\fBrawcounts\\fR; this letter wins over all others.
.TP
\\fBq\\fR
Incremental encoder on \\fBrawcounts\\fR; the rotor must be aligned first.
.TP
\\fBi\\fR
With \\fBq\\fR: the encoder index is the reference (\\fBindex-enable\\fR).
.TP
\\fBf\\fR
Fanuc 4-bit Gray code on \\fBC1\\fR, \\fBC2\\fR, \\fBC4\\fR, \\fBC8\\fR.
.PP
Output letters (upper case); without any, three bipolar amplitudes
\\fBA-value\\fR, \\fBB-value\\fR, \\fBC-value\\fR:
.TP
\\fBB\\fR
Logic outputs instead of amplitudes: \\fBA-on\\fR..\\fBC-on\\fR, or with
\\fB6\\fR the six gate signals \\fBA-high-on\\fR..\\fBC-low-on\\fR.
.TP
\\fB6\\fR
Six outputs, a positive amplitude for the high and for the low side of
each phase (\\fBA-high\\fR..\\fBC-low\\fR).
.TP
\\fBH\\fR
Emulated Hall sensors (\\fBhall1-out\\fR..\\fBhall3-out\\fR, coded by
\\fBoutput-pattern\\fR) for a drive that expects Halls.
.TP
\\fBF\\fR
Emulated Fanuc Gray code (\\fBC1-out\\fR..\\fBC8-out\\fR).
.TP
\\fBT\\fR
Trapezoidal (block) commutation even where sinusoidal is possible.
.PP
Angles (\\fBrotor-angle\\fR, \\fBphase-angle\\fR) are in electrical
revolutions, 0 to 1.  With sinusoidal commutation the phase amplitudes are
|\\fBvalue\\fR| * cos(2\\(*p * (phase-angle - k/3)) for A, B and C (k = 0,
1, 2); the phase angle is the rotor angle plus \\fBlead-angle\\fR (minus it
when reversed).  With trapezoidal commutation one phase is driven at
+|\\fBvalue\\fR|, one at -|\\fBvalue\\fR| and one is left at 0, six steps
per electrical revolution.  A negative \\fBvalue\\fR, or \\fBrev\\fR TRUE,
turns the motor the other way; with an encoder the count used is the raw
count plus half of its change in the last period, to make up for the delay
of one period.  The first period after loading only sets the component up
(\\fBin-type\\fR and \\fBout-type\\fR show the result).
""";

notes """
\\fBHall patterns\\fR (\\fBpattern\\fR, \\fBoutput-pattern\\fR): the Hall state, as H1 H2 H3,
that each pattern gives while the phases named at the top are driven (the
first from + to the second at -).
.nf
pattern  B-A  C-A  C-B  A-B  A-C  B-C
      0  000  001  011  111  110  100
      1  001  000  010  110  111  101
      2  000  010  011  111  101  100
      3  001  011  010  110  100  101
      4  010  011  001  101  100  110
      5  011  010  000  100  101  111
      6  010  000  001  101  111  110
      7  011  001  000  100  110  111
      8  000  001  101  111  110  010
      9  001  000  100  110  111  011
     10  000  010  110  111  101  001
     11  001  011  111  110  100  000
     12  010  011  111  101  100  000
     13  011  010  110  100  101  001
     14  010  000  100  101  111  011
     15  011  001  101  100  110  010
     16  000  100  101  111  011  010
     17  001  101  100  110  010  011
     18  000  100  110  111  011  001
     19  001  101  111  110  010  000
     20  010  110  111  101  001  000
     21  011  111  110  100  000  001
     22  010  110  100  101  001  011
     23  011  111  101  100  000  010
     24  100  101  111  011  010  000
     25  101  100  110  010  011  001
     26  100  110  111  011  001  000
     27  101  111  110  010  000  001
     28  110  111  101  001  000  010
     29  111  110  100  000  001  011
     30  110  100  101  001  011  010
     31  111  101  100  000  010  011
     32  100  101  001  011  010  110
     33  101  100  000  010  011  111
     34  100  110  010  011  001  101
     35  101  111  011  010  000  100
     36  110  111  011  001  000  100
     37  111  110  010  000  001  101
     38  110  100  000  001  011  111
     39  111  101  001  000  010  110
     40  100  000  001  011  111  110
     41  101  001  000  010  110  111
     42  100  000  010  011  111  101
     43  101  001  011  010  110  100
     44  110  010  011  001  101  100
     45  111  011  010  000  100  101
     46  110  010  000  001  101  111
     47  111  011  001  000  100  110
.fi

\\fBqh\\fR: the motor is run by the Halls (block commutation) until the first
Hall edge; the rotor is then on the boundary of two Hall sectors, and the
encoder count there gives \\fBoffset-measured\\fR, from which on the
encoder angle (with \\fBlead-angle\\fR) commutes sinusoidally.

\\fBNot yet in halsdk:\\fR the rotor alignment of \\fBq\\fR (magnetic
homing on \\fBinit\\fR) and the index homing of \\fBqi\\fR and
\\fBqhi\\fR: instances with these letters do not drive their outputs yet.
""";

pin in bit hall1 if personality & 0x01 "Hall sensor 1";
pin in bit hall2 if personality & 0x01 "Hall sensor 2";
pin in bit hall3 if personality & 0x01 "Hall sensor 3";
pin out bit hall_error if personality & 0x01 "Set (and kept) when the Hall state is not in the selected pattern (000, 111, ...) or jumps by more than one step: the pattern does not fit the motor or a sensor is faulty";

pin in bit C1 if (personality & 0x10) "Fanuc Gray code input, bit 0";
pin in bit C2 if (personality & 0x10) "Fanuc Gray code input, bit 1";
pin in bit C4 if (personality & 0x10) "Fanuc Gray code input, bit 2";
pin in bit C8 if (personality & 0x10) "Fanuc Gray code input, bit 3";

pin in float value "Amplitude of the phase outputs (the current or PWM demand); its sign sets the direction";
pin in float lead_angle if personality & 0x06 = 90 "Angle, in electrical degrees, between the rotor position and the field the phases make";
pin in bit rev "TRUE reverses the motor (as a negative value does)";
pin in float frequency if (personality & 0x0F) == 0 "Speed of the turning field, electrical revolutions per second, without feedback";
pin in float initvalue if personality & 0x04 = 0.2 "Amplitude used while aligning the rotor (incremental encoder without Halls)";
pin in s32 rawcounts if personality & 0x06 = 0 "Encoder counts: connect to the raw counts of the encoder, which an index does not reset";
pin io bit index_enable if personality & 0x08 "Connect to index-enable of the encoder: tells the component that the index was seen";
pin in bit init if (personality & 0x05) == 4 "A rising edge starts the rotor alignment (needed after every loss of the encoder position, e.g. at power on; before the axis is enabled)";
pin out bit init_done if (personality & 0x05) == 4 = 0 "TRUE when the alignment is complete";

pin out float A_value if (personality & 0xF00) == 0 "Amplitude of phase A";
pin out float B_value if (personality & 0xF00) == 0 "Amplitude of phase B";
pin out float C_value if (personality & 0xF00) == 0 "Amplitude of phase C";
pin out bit A_on if (personality & 0xF00) == 0x100 "Phase A switched high (FALSE: low; a phase left open keeps its state)";
pin out bit B_on if (personality & 0xF00) == 0x100 "Phase B switched high";
pin out bit C_on if (personality & 0xF00) == 0x100 "Phase C switched high";
pin out float A_high if (personality & 0xF00) == 0x200 "High side amplitude of phase A (0 or more)";
pin out float B_high if (personality & 0xF00) == 0x200 "High side amplitude of phase B";
pin out float C_high if (personality & 0xF00) == 0x200 "High side amplitude of phase C";
pin out float A_low if (personality & 0xF00) == 0x200 "Low side amplitude of phase A (0 or more)";
pin out float B_low if (personality & 0xF00) == 0x200 "Low side amplitude of phase B";
pin out float C_low if (personality & 0xF00) == 0x200 "Low side amplitude of phase C";
pin out bit A_high_on if (personality & 0xF00) == 0x300 "High side switch of phase A";
pin out bit B_high_on if (personality & 0xF00) == 0x300 "High side switch of phase B";
pin out bit C_high_on if (personality & 0xF00) == 0x300 "High side switch of phase C";
pin out bit A_low_on if (personality & 0xF00) == 0x300 "Low side switch of phase A";
pin out bit B_low_on if (personality & 0xF00) == 0x300 "Low side switch of phase B";
pin out bit C_low_on if (personality & 0xF00) == 0x300 "Low side switch of phase C";
pin out bit hall1_out if (personality & 0x400) "Emulated Hall sensor 1";
pin out bit hall2_out if (personality & 0x400) "Emulated Hall sensor 2";
pin out bit hall3_out if (personality & 0x400) "Emulated Hall sensor 3";
pin out bit C1_out if (personality & 0x800) "Emulated Fanuc Gray code, bit 0";
pin out bit C2_out if (personality & 0x800) "Emulated Fanuc Gray code, bit 1";
pin out bit C4_out if (personality & 0x800) "Emulated Fanuc Gray code, bit 2";
pin out bit C8_out if (personality & 0x800) "Emulated Fanuc Gray code, bit 3";

pin out float phase_angle = 0 "Angle of the field made by the phases, electrical revolutions (0 to 1), lead included: for drives that take an angle and a current";
pin out float rotor_angle = 0 "Angle of the rotor, electrical revolutions (0 to 1): for drives that add their own lead, such as the Mesa 8i20";
pin out float out "value, negated when rev is TRUE";
pin out bit out_dir "TRUE when value is negative or rev is TRUE (not both); FALSE while value is 0 or NaN";
pin out float out_abs "Absolute value of value";

param r s32 in_type = -1 "Feedback mode in use, worked out in the first period (-1 before; -2: the letters make no usable feedback)";
param r s32 out_type = -1 "Output mode in use, worked out in the first period";
param rw s32 scale if personality & 0x06 = 512 "Encoder counts per mechanical revolution";
param rw s32 poles if personality & 0x06 = 4 "Number of motor poles (twice the electrical revolutions per mechanical one)";
param rw s32 encoder_offset if personality & 0x0A = 0 "Encoder count at the electrical zero of the motor";
param r s32 offset_measured if personality & 0x04 = 0 "Encoder offset found by the alignment";
param rw float drive_offset = 0 "Angle, in degrees, the drive adds to a commanded angle; only used while aligning, for drives that take a rotor angle.  0 for most drives";
param rw u32 output_pattern if personality & 0x400 = 25 "Hall pattern (0 to 47, see pattern) of the emulated Hall outputs";
param rw u32 pattern if personality & 0x01 = 25 "Hall pattern of the motor, 0 to 47 (default 25).  Each pattern lists the Hall states H1 H2 H3 for the six excitations B-A, C-A, C-B, A-B, A-C, B-C (source - sink); see the table in the notes.  Common ones: 0 (30 degree) and 26 (its reverse), 17 (120 degree), 18 (alternate 60 degree), 21 (300 degree, Bodine), 22 (240 degree), 25 (60 degree).  A pattern with a non-zero torque is not necessarily right; with no documentation, try them all";

variable int prev_raw;
variable int last_k;
variable int bits[3];
variable int homed;         /* qh: a Hall edge has given the encoder offset */
variable int zero_count;    /* qh: encoder count at electrical zero */

modparam dummy cfg "Letters of each instance, comma separated, e.g. cfg=qi6,aH";

function _ "Read the feedback and update the phase outputs";

option count_function;

see_also "encoder(9)";
author "the halsdk authors";
license "GPL";
;;
#include <rtapi_math.h>

#define MAX_INST 8

#define P_HALL   0x01
#define P_ABS    0x02
#define P_QUAD   0x04
#define P_INDEX  0x08
#define P_FANUC  0x10
#define P_BITS   0x100
#define P_SIX    0x200
#define P_HOUT   0x400
#define P_FOUT   0x800
#define P_TRAP   0x1000

static char *cfg[MAX_INST];
RTAPI_MP_ARRAY_STRING(cfg, MAX_INST, "letters of each instance");

/* Hall states (H1 as bit 2) of each pattern for the excitations
   B-A, C-A, C-B, A-B, A-C, B-C */
static const unsigned char table[48][6] = {
    {0, 1, 3, 7, 6, 4}, {1, 0, 2, 6, 7, 5}, {0, 2, 3, 7, 5, 4}, {1, 3, 2, 6, 4, 5},
    {2, 3, 1, 5, 4, 6}, {3, 2, 0, 4, 5, 7}, {2, 0, 1, 5, 7, 6}, {3, 1, 0, 4, 6, 7},
    {0, 1, 5, 7, 6, 2}, {1, 0, 4, 6, 7, 3}, {0, 2, 6, 7, 5, 1}, {1, 3, 7, 6, 4, 0},
    {2, 3, 7, 5, 4, 0}, {3, 2, 6, 4, 5, 1}, {2, 0, 4, 5, 7, 3}, {3, 1, 5, 4, 6, 2},
    {0, 4, 5, 7, 3, 2}, {1, 5, 4, 6, 2, 3}, {0, 4, 6, 7, 3, 1}, {1, 5, 7, 6, 2, 0},
    {2, 6, 7, 5, 1, 0}, {3, 7, 6, 4, 0, 1}, {2, 6, 4, 5, 1, 3}, {3, 7, 5, 4, 0, 2},
    {4, 5, 7, 3, 2, 0}, {5, 4, 6, 2, 3, 1}, {4, 6, 7, 3, 1, 0}, {5, 7, 6, 2, 0, 1},
    {6, 7, 5, 1, 0, 2}, {7, 6, 4, 0, 1, 3}, {6, 4, 5, 1, 3, 2}, {7, 5, 4, 0, 2, 3},
    {4, 5, 1, 3, 2, 6}, {5, 4, 0, 2, 3, 7}, {4, 6, 2, 3, 1, 5}, {5, 7, 3, 2, 0, 4},
    {6, 7, 3, 1, 0, 4}, {7, 6, 2, 0, 1, 5}, {6, 4, 0, 1, 3, 7}, {7, 5, 1, 0, 2, 6},
    {4, 0, 1, 3, 7, 6}, {5, 1, 0, 2, 6, 7}, {4, 0, 2, 3, 7, 5}, {5, 1, 3, 2, 6, 4},
    {6, 2, 3, 1, 5, 4}, {7, 3, 2, 0, 4, 5}, {6, 2, 0, 1, 5, 7}, {7, 3, 1, 0, 4, 6},
};

/* source (+) and sink (-) phase of each excitation, A = 0 */
static const int src[6] = {1, 2, 2, 0, 0, 1};
static const int snk[6] = {0, 0, 1, 1, 2, 2};

#undef personality
static int get_count(void)
{
    int n, p;
    const char *c;

    if (cfg[0] == NULL) {
        rtapi_print_msg(RTAPI_MSG_ERR, "The bldc component needs at least "
                        "one feedback type tag.\nValid tags are h, a, q, "
                        "i, b, 6, n\n");
        return 0;
    }
    for (n = 0; n < MAX_INST && cfg[n] != NULL; n++) {
        p = 0;
        for (c = cfg[n]; *c; c++) {
            switch (*c) {
            case 'h': p |= P_HALL; break;
            case 'a': p |= P_ABS; break;
            case 'q': p |= P_QUAD; break;
            case 'i': p |= P_INDEX; break;
            case 'f': p |= P_FANUC; break;
            case 'B': p |= P_BITS; break;
            case '6': p |= P_SIX; break;
            case 'H': p |= P_HOUT; break;
            case 'F': p |= P_FOUT; break;
            case 'T': p |= P_TRAP; break;
            default: break;     /* n and unknown letters add nothing */
            }
        }
        personality[n] = p;
    }
    return n;
}
#define personality (__comp_inst->_personality)

static double wrap(double x)
{
    return x - floor(x);
}

/* the sixth of a revolution (0..5) nearest to an angle */
static int sixth(double angle)
{
    int s = (int)ceil(angle * 6 + 0.5) - 1;
    return ((s % 6) + 6) % 6;
}

/* rotor angle from encoder counts: the count plus half its last change
   (the delay of one period), less the offset, times the electrical
   revolutions per turn (integer arithmetic), over the counts per turn */
static double encoder_angle(int now, int before, int zero, int npoles,
                            int counts)
{
    int c = now + (now - before) / 2 - zero;
    int m = c * npoles / 2;
    return wrap((double)m / counts);
}

static int gray(int n)
{
    return n ^ (n >> 1);
}

FUNCTION(_) {
    double amp[3] = {0, 0, 0};
    double a;
    int dir, k, e = -1, i, raw = 0, pos6 = -1;
    int sine, valid = 1;

    out_abs = fabs(value);
    /* out-dir, from the first period on, as the reference: the sign of
       value turned round by rev, FALSE for a value of 0 or NaN */
    out_dir = value > 0 ? (rev != 0) : (value < 0 ? (rev == 0) : 0);
    if (personality & 0x06)
        raw = rawcounts;

    if (in_type == -1) {
        /* first period: note the modes, the encoder and ask for the index */
        in_type = personality & 0xFF;
        out_type = personality & 0xF00;
        prev_raw = raw;
        last_k = -1;
        if (personality & P_INDEX)
            index_enable = 1;
        return;
    }

    /* second period: settle letter combinations that need it */
    switch (in_type) {
    case 0: case P_HALL: case P_ABS: case P_QUAD: case P_QUAD | P_HALL:
    case P_QUAD | P_INDEX: case P_QUAD | P_INDEX | P_HALL: case P_FANUC:
        break;
    case P_ABS | P_HALL:
        rtapi_print_msg(RTAPI_MSG_ERR, "Both Hall Sensors and Absolute "
                        "encoder specified on the same motor. Only the"
                        "Encoder will be used\n");
        in_type = P_ABS;
        return;
    case P_ABS | P_INDEX:
        rtapi_print_msg(RTAPI_MSG_ERR, "Index is not needed with an Absolute"
                        "encoder and will be ignored\n");
        in_type = P_ABS;
        return;
    case P_HALL | P_INDEX:
        rtapi_print_msg(RTAPI_MSG_ERR, "The use of an encoder Index with Hall "
                        "sensors is not supported. Defaulting to trapezoidal "
                        "commutation\n");
        in_type = P_HALL;
        return;
    case P_ABS | P_QUAD:
        rtapi_print_msg(RTAPI_MSG_ERR, "Specifying the use of both absolute "
                        "and incremental encoders on the same motor is an "
                        "error. Motor disabled\n");
        in_type = -2;
        return;
    case P_INDEX:
        rtapi_print_msg(RTAPI_MSG_ERR, "Driving an electronically commutated"
                        "motor with only an index for feedback is not"
                        "possible. Motor Disabled\n");
        in_type = -2;
        return;
    case -2:
        return;                 /* no usable feedback: the motor is off */
    default:
        rtapi_print_msg(RTAPI_MSG_ERR, "Unknown input type pattern (%x) in "
                        "bldc\n", in_type);
        in_type = -2;
        return;
    }

    /* Hall outputs go with neither logic nor six outputs */
    if ((out_type & P_HOUT) && (out_type & (P_BITS | P_SIX))) {
        if (out_type & P_SIX)
            rtapi_print_msg(RTAPI_MSG_ERR, "6-Wire Hall patterns outputs are "
                            "not supported. Defaulting to 3-wire\n");
        if (out_type & P_BITS)
            rtapi_print_msg(RTAPI_MSG_ERR, "Combinations of Hall Pattern and "
                            "Bit outputs are not supported. Defaulting to "
                            "Hall\n");
        out_type = P_HOUT;
    }

    dir = (value < 0) ^ (rev != 0);
    out = dir ? -out_abs : out_abs;

    sine = !(personality & P_TRAP) && (out_type & P_BITS) == 0;
    switch (in_type) {
    case 0:                     /* no feedback: a free-running field */
        rotor_angle = wrap(rotor_angle + frequency * fperiod);
        phase_angle = rotor_angle;
        break;
    case P_FANUC: {
        /* 4-bit Gray code: sixteen sectors, the rotor in the middle of one */
        int g = (C1 ? 1 : 0) | (C2 ? 2 : 0) | (C4 ? 4 : 0) | (C8 ? 8 : 0);
        int n = g ^ (g >> 1);
        n ^= n >> 2;
        rotor_angle = (n + 0.5) / 16.0;
        phase_angle = wrap(rotor_angle + (dir ? -0.25 : 0.25));
        break;
    }
    case P_QUAD | P_HALL:
        if (homed) {
            rotor_angle = encoder_angle(raw, prev_raw, zero_count, poles, scale);
            a = lead_angle / 360.0;
            phase_angle = wrap(rotor_angle + (dir ? -a : a));
            break;
        }
        /* not homed yet: Hall commutation until the first Hall edge */
        /* fall through */
    case P_HALL: {
        unsigned h = (hall1 ? 4 : 0) | (hall2 ? 2 : 0) | (hall3 ? 1 : 0);
        unsigned pt = pattern < 48 ? pattern : 25;
        sine = 0;
        for (k = 0; k < 6 && table[pt][k] != h; k++)
            ;
        if (k == 6) {
            /* no such state: outputs off, the angles fall back to 0 */
            hall_error = 1;
            valid = 0;
            rotor_angle = 0;
            phase_angle = dir ? 0.25 : 0.75;
            break;
        }
        pos6 = k;
        e = dir ? (k + 3) % 6 : k;
        rotor_angle = wrap((k + 1) / 6.0);
        phase_angle = wrap(rotor_angle + (dir ? 0.25 : 0.75));
        if (last_k >= 0 && k != last_k) {
            int lo = -1;
            if ((last_k + 1) % 6 == k)
                lo = last_k;
            else if ((k + 1) % 6 == last_k)
                lo = k;
            else
                hall_error = 1;
            if (lo >= 0 && in_type == (P_QUAD | P_HALL)) {
                /* a Hall edge: the rotor is on the boundary of two
                   sectors; note the encoder count there */
                double edge = wrap((lo + 1.5) / 6.0);
                zero_count = raw - (int)(edge * scale * 2.0 / poles);
                offset_measured = zero_count;
                rotor_angle = edge;
                phase_angle = wrap(edge + (dir ? -0.25 : 0.25));
                homed = 1;
            }
        }
        last_k = k;
        break;
    }
    case P_ABS:
        rotor_angle = encoder_angle(raw, prev_raw, encoder_offset, poles,
                                    scale);
        a = lead_angle / 360.0;
        phase_angle = wrap(rotor_angle + (dir ? -a : a));
        break;
    default:
        valid = 0;
        break;
    }

    if (valid && e < 0) {
        /* block steps centred on the rotor sixths, turned round in reverse;
           an exact boundary counts to the step below */
        e = (sixth(rotor_angle) + (dir ? 3 : 0)) % 6;
    }
    if (valid) {
        if (sine) {
            for (i = 0; i < 3; i++)
                amp[i] = out_abs * cos(2 * M_PI * (phase_angle - i / 3.0));
        } else {
            amp[src[e]] = out_abs;
            amp[snk[e]] = -out_abs;
        }
    }

    prev_raw = raw;

    switch (out_type) {
    case 0:
        A_value = amp[0];
        B_value = amp[1];
        C_value = amp[2];
        break;
    case P_BITS:
        /* a phase left open keeps its state; all off without feedback */
        for (i = 0; i < 3; i++) {
            if (!valid)
                bits[i] = 0;
            else if (amp[i] > 0)
                bits[i] = 1;
            else if (amp[i] < 0)
                bits[i] = 0;
        }
        A_on = bits[0];
        B_on = bits[1];
        C_on = bits[2];
        break;
    case P_SIX:
        A_high = amp[0] > 0 ? amp[0] : 0;
        A_low = amp[0] < 0 ? -amp[0] : 0;
        B_high = amp[1] > 0 ? amp[1] : 0;
        B_low = amp[1] < 0 ? -amp[1] : 0;
        C_high = amp[2] > 0 ? amp[2] : 0;
        C_low = amp[2] < 0 ? -amp[2] : 0;
        break;
    case P_BITS | P_SIX:
        A_high_on = amp[0] > 0;
        A_low_on = amp[0] < 0;
        B_high_on = amp[1] > 0;
        B_low_on = amp[1] < 0;
        C_high_on = amp[2] > 0;
        C_low_on = amp[2] < 0;
        break;
    }

    if (out_type & P_HOUT) {
        unsigned op = output_pattern < 48 ? output_pattern : 25;
        unsigned h;
        /* the Hall state of the rotor position: the decoded one with Halls,
           else the nearest sixth of a revolution */
        if (pos6 < 0)
            pos6 = sixth(rotor_angle);
        h = valid ? table[op][pos6] : 0;
        hall1_out = (h >> 2) & 1;
        hall2_out = (h >> 1) & 1;
        hall3_out = h & 1;
    }
    if (out_type & P_FOUT) {
        /* sixteenths of a revolution, an exact boundary counting to the
           sixteenth below (as the reference does) */
        int n16 = (int)ceil(rotor_angle * 16) - 1;
        int g = valid ? gray(n16 < 0 ? 0 : n16 & 15) : 0;
        C1_out = g & 1;
        C2_out = (g >> 1) & 1;
        C4_out = (g >> 2) & 1;
        C8_out = (g >> 3) & 1;
    }
}
