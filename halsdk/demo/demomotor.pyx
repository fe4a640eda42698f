# A simulated DC motor driving an inertia: J dv/dt = kt*voltage - b*v -
# friction*sign(v); the position is integrated and reported through a
# quantized encoder with `counts-per-unit` resolution.

from libc.math cimport floor

from halsdk cimport hal

hal.import_halsdk()

cdef struct motor_t:
    hal.hal_float_t *voltage
    hal.hal_float_t *velocity
    hal.hal_float_t *position
    hal.hal_float_t *encoder
    hal.hal_float_t inertia
    hal.hal_float_t torque_constant
    hal.hal_float_t damping
    hal.hal_float_t friction
    hal.hal_float_t counts_per_unit
    double v
    double x


cdef void update(void *arg, long period) noexcept nogil:
    cdef motor_t *m = <motor_t *>arg
    cdef double dt = period * 1e-9
    cdef double torque = m.torque_constant * m.voltage[0] - m.damping * m.v
    if m.v > 0:
        torque -= m.friction
    elif m.v < 0:
        torque += m.friction
    elif -m.friction < torque < m.friction:
        torque = 0                       # static friction holds it
    m.v += torque / m.inertia * dt
    m.x += m.v * dt
    m.velocity[0] = m.v
    m.position[0] = m.x
    m.encoder[0] = floor(m.x * m.counts_per_unit) / m.counts_per_unit


modparams = {"count": (int, 1, "number of motors")}

cdef int comp_id = -1


def setup(count=1):
    global comp_id
    cdef motor_t *m
    cdef int i
    comp_id = hal.hal_init(b"demomotor")
    if comp_id < 0:
        raise RuntimeError("hal_init failed")
    for i in range(count):
        m = <motor_t *>hal.hal_malloc(sizeof(motor_t))
        if m == NULL:
            raise MemoryError("hal_malloc failed")
        m.inertia = 0.01
        m.torque_constant = 1.0
        m.damping = 0.05
        m.friction = 0.02
        m.counts_per_unit = 4000
        if (hal.hal_pin_float_newf(hal.HAL_IN, &m.voltage, comp_id,
                                   b"demomotor.%d.voltage", i) < 0
                or hal.hal_pin_float_newf(hal.HAL_OUT, &m.velocity, comp_id,
                                          b"demomotor.%d.velocity", i) < 0
                or hal.hal_pin_float_newf(hal.HAL_OUT, &m.position, comp_id,
                                          b"demomotor.%d.position", i) < 0
                or hal.hal_pin_float_newf(hal.HAL_OUT, &m.encoder, comp_id,
                                          b"demomotor.%d.encoder", i) < 0
                or hal.hal_param_float_newf(hal.HAL_RW, &m.inertia, comp_id,
                                            b"demomotor.%d.inertia", i) < 0
                or hal.hal_param_float_newf(
                    hal.HAL_RW, &m.torque_constant, comp_id,
                    b"demomotor.%d.torque-constant", i) < 0
                or hal.hal_param_float_newf(hal.HAL_RW, &m.damping, comp_id,
                                            b"demomotor.%d.damping", i) < 0
                or hal.hal_param_float_newf(hal.HAL_RW, &m.friction, comp_id,
                                            b"demomotor.%d.friction", i) < 0
                or hal.hal_param_float_newf(
                    hal.HAL_RW, &m.counts_per_unit, comp_id,
                    b"demomotor.%d.counts-per-unit", i) < 0
                or hal.hal_export_functf(update, m, 1, 0, comp_id,
                                         b"demomotor.%d.update", i) < 0):
            raise RuntimeError(f"demomotor.{i}: cannot create its pins")
    hal.hal_ready(comp_id)


def cleanup():
    global comp_id
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1
