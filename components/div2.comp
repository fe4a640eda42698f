component div2 "Quotient of two signals, with a deadband for the divisor";

pin in float in0 "The dividend";
pin in float in1 "The divisor";
pin out float out "in0 / in1; see deadband for divisors close to zero";

param rw float deadband """While |in1| < deadband, out is in0 divided by
+deadband (in1 >= 0, -0.0 included) or by -deadband (in1 < 0) instead of
in1, so out stays finite. Values below 1e-12 (0 too) are raised to 1e-12""";

function _ "Compute out";

description """Divides in0 by in1. A divisor near zero does not make out
explode: it is replaced by the deadband value of the same sign.""";
notes """When a divisor first falls into the deadband, a warning is printed
(once for all instances of the module, until some instance sees a divisor
outside its deadband again).""";
see_also "mult2(9), invert(9)";
author "the halsdk authors";
license "GPL";
;;
/* set once a warning has been printed; cleared by any instance whose
   divisor is outside its deadband */
static int warned;

static void warn(char sign)
{
    if (warned)
        return;
    warned = 1;
    rtapi_print_msg(RTAPI_MSG_ERR,
                    "\n DIV2 DIVISOR IS TOO CLOSE TO %cZERO,\n"
                    " THEREFORE %cDEADBAND IS USED.\n"
                    " INCREASE THE DIVISOR, in1.\n", sign, sign);
}

FUNCTION(_) {
    double d = in1;

    if (deadband < 1e-12)
        deadband = 1e-12;
    if (d >= 0 && d < deadband) {
        warn('+');
        d = deadband;
    } else if (d < 0 && d > -deadband) {
        warn('-');
        d = -deadband;
    } else {
        warned = 0;
    }
    out = in0 / d;
}
