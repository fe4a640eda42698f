# A compact PID controller for the demo (the full reference `pid` comes
# with the component library): output = P*e + I*integral(e) + D*de/dt +
# FF1*d(command)/dt, clamped to +-maxoutput, with anti-windup.

from halsdk cimport hal

hal.import_halsdk()

cdef struct pid_t:
    hal.hal_bit_t *enable
    hal.hal_float_t *command
    hal.hal_float_t *feedback
    hal.hal_float_t *error
    hal.hal_float_t *output
    hal.hal_float_t pgain
    hal.hal_float_t igain
    hal.hal_float_t dgain
    hal.hal_float_t ff1gain
    hal.hal_float_t maxoutput
    double integral
    double last_error
    double last_command


cdef void update(void *arg, long period) noexcept nogil:
    cdef pid_t *p = <pid_t *>arg
    cdef double dt = period * 1e-9
    cdef double e = p.command[0] - p.feedback[0]
    cdef double out
    p.error[0] = e
    if not p.enable[0]:
        p.integral = 0
        p.last_error = e
        p.last_command = p.command[0]
        p.output[0] = 0
        return
    p.integral += e * dt
    out = (p.pgain * e + p.igain * p.integral
           + p.dgain * (e - p.last_error) / dt
           + p.ff1gain * (p.command[0] - p.last_command) / dt)
    if p.maxoutput > 0 and out > p.maxoutput:
        p.integral -= e * dt            # do not wind up while saturated
        out = p.maxoutput
    elif p.maxoutput > 0 and out < -p.maxoutput:
        p.integral -= e * dt
        out = -p.maxoutput
    p.last_error = e
    p.last_command = p.command[0]
    p.output[0] = out


modparams = {"count": (int, 1, "number of controllers")}

cdef int comp_id = -1


def setup(count=1):
    global comp_id
    cdef pid_t *p
    cdef int i
    comp_id = hal.hal_init(b"demopid")
    if comp_id < 0:
        raise RuntimeError("hal_init failed")
    for i in range(count):
        p = <pid_t *>hal.hal_malloc(sizeof(pid_t))
        if p == NULL:
            raise MemoryError("hal_malloc failed")
        if (hal.hal_pin_bit_newf(hal.HAL_IN, &p.enable, comp_id,
                                 b"demopid.%d.enable", i) < 0
                or hal.hal_pin_float_newf(hal.HAL_IN, &p.command, comp_id,
                                          b"demopid.%d.command", i) < 0
                or hal.hal_pin_float_newf(hal.HAL_IN, &p.feedback, comp_id,
                                          b"demopid.%d.feedback", i) < 0
                or hal.hal_pin_float_newf(hal.HAL_OUT, &p.error, comp_id,
                                          b"demopid.%d.error", i) < 0
                or hal.hal_pin_float_newf(hal.HAL_OUT, &p.output, comp_id,
                                          b"demopid.%d.output", i) < 0
                or hal.hal_param_float_newf(hal.HAL_RW, &p.pgain, comp_id,
                                            b"demopid.%d.Pgain", i) < 0
                or hal.hal_param_float_newf(hal.HAL_RW, &p.igain, comp_id,
                                            b"demopid.%d.Igain", i) < 0
                or hal.hal_param_float_newf(hal.HAL_RW, &p.dgain, comp_id,
                                            b"demopid.%d.Dgain", i) < 0
                or hal.hal_param_float_newf(hal.HAL_RW, &p.ff1gain, comp_id,
                                            b"demopid.%d.FF1", i) < 0
                or hal.hal_param_float_newf(hal.HAL_RW, &p.maxoutput,
                                            comp_id, b"demopid.%d.maxoutput",
                                            i) < 0
                or hal.hal_export_functf(update, p, 1, 0, comp_id,
                                         b"demopid.%d.do-pid-calcs", i) < 0):
            raise RuntimeError(f"demopid.{i}: cannot create its pins")
    hal.hal_ready(comp_id)


def cleanup():
    global comp_id
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1
