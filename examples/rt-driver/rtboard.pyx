# rtboard: realtime driver for a simulated memory-mapped I/O board.
#
#     loadrt rtboard [boards=N] [loopback=0|1]
#
# Each board has 4 digital inputs, 4 digital outputs, 2 ADC inputs
# (12 bit), 2 DAC outputs (16 bit, signed) and 2 encoders with 16-bit
# counters and an index latch.  Board N gets the canonical pins
# rtboard.N.<io-type>.<chan>.<name>, the fault pins rtboard.N.fault,
# .fault-code and .fault-count, and the functions rtboard.N.read and
# rtboard.N.write.
#
# The "board" is a block of 32-bit registers that setup() allocates in
# HAL shared memory; on real hardware it would be a mapped PCI BAR.  The
# Python functions peek() and poke() play the other side of the bus for
# tests.  With loopback=1 the simulated hardware feeds the outputs back to
# the inputs at the end of every write (see sim_hardware).

from halsdk cimport hal
from halsdk.driverkit cimport rt

hal.import_halsdk()

# ---------------------------------------------------------------------
# The register map (32-bit words)

cdef enum:
    MAX_BOARDS = 4
    NUM_DIGIN = 4
    NUM_DIGOUT = 4
    NUM_ADCIN = 2
    NUM_DACOUT = 2
    NUM_ENCODER = 2
    ENCODER_BITS = 16

    REG_STATUS = 0          # bit 0: the board answers
    REG_DIN = 1             # bit i: digital input i
    REG_DOUT = 2            # bit i: digital output i
    REG_ADC = 3             # 2 words: ADC counts, 0..4095
    REG_DAC = 5             # 2 words: DAC counts, -32768..32767
    REG_ENC = 7             # 2 words: encoder counters, 16 bit
    REG_ENC_LATCH = 9       # 2 words: counter at the last index pulse
    REG_ENC_INDEX = 11      # bit i: encoder i saw an index (write 0 to ack)
    NUM_REGS = 12

    STATUS_READY = 1

REGISTERS = {
    "status": REG_STATUS, "din": REG_DIN, "dout": REG_DOUT,
    "adc0": REG_ADC, "adc1": REG_ADC + 1, "dac0": REG_DAC,
    "dac1": REG_DAC + 1, "enc0": REG_ENC, "enc1": REG_ENC + 1,
    "latch0": REG_ENC_LATCH, "latch1": REG_ENC_LATCH + 1,
    "index": REG_ENC_INDEX,
}


cdef struct board_t:
    unsigned int *regs          # the register block ("mapped memory")
    int loopback
    rt.device_t dev
    rt.digin_t din[NUM_DIGIN]
    rt.digout_t dout[NUM_DIGOUT]
    rt.adcin_t adc[NUM_ADCIN]
    rt.dacout_t dac[NUM_DACOUT]
    rt.encoder_t enc[NUM_ENCODER]


cdef board_t *board_ptr[MAX_BOARDS]
cdef int num_boards = 0
cdef int comp_id = -1


# ---------------------------------------------------------------------
# Realtime functions: no GIL, no allocation, no Python

cdef void board_read(void *arg, long period) noexcept nogil:
    cdef board_t *b = <board_t *>arg
    cdef unsigned int *regs = b.regs
    cdef unsigned int din, index
    cdef int i

    if not (regs[REG_STATUS] & STATUS_READY):
        rt.device_fault(&b.dev, rt.RT_FAULT_READ, b"board does not answer")
        return                  # inputs keep their last values
    din = regs[REG_DIN]
    for i in range(NUM_DIGIN):
        rt.digin_update(&b.din[i], din & (1u << i))
    for i in range(NUM_ADCIN):
        rt.adcin_update_counts(&b.adc[i], regs[REG_ADC + i] & 0xfff)
    index = regs[REG_ENC_INDEX]
    for i in range(NUM_ENCODER):
        if index & (1u << i):
            rt.encoder_index(&b.enc[i], regs[REG_ENC_LATCH + i])
        rt.encoder_update(&b.enc[i], regs[REG_ENC + i], period)
    regs[REG_ENC_INDEX] = 0     # acknowledge the latches
    rt.device_ok(&b.dev)


cdef void board_write(void *arg, long period) noexcept nogil:
    cdef board_t *b = <board_t *>arg
    cdef unsigned int *regs = b.regs
    cdef unsigned int dout = 0
    cdef long long counts
    cdef int i

    if not (regs[REG_STATUS] & STATUS_READY):
        rt.device_fault(&b.dev, rt.RT_FAULT_WRITE, b"board does not answer")
        return
    for i in range(NUM_DIGOUT):
        if rt.digout_raw(&b.dout[i]):
            dout |= 1u << i
    regs[REG_DOUT] = dout
    for i in range(NUM_DACOUT):
        counts = rt.dacout_counts(&b.dac[i])
        if counts > 32767:
            counts = 32767
        elif counts < -32768:
            counts = -32768
        regs[REG_DAC + i] = <unsigned int><int>counts
    if b.loopback:
        sim_hardware(regs)


cdef void sim_hardware(unsigned int *regs) noexcept nogil:
    # SIMULATION ONLY: what the board's wiring would do in a loopback
    # test rig.  Outputs drive the inputs, each DAC drives its ADC (12 bit
    # over the DAC's range) and moves its encoder by counts/256 a cycle.
    cdef int i, dac
    regs[REG_DIN] = regs[REG_DOUT]
    for i in range(NUM_DACOUT):
        dac = <int>regs[REG_DAC + i]
        regs[REG_ADC + i] = <unsigned int>((dac + 32768) >> 4)
        regs[REG_ENC + i] = (regs[REG_ENC + i] + <unsigned int>(dac // 256)) \
            & 0xffff


# ---------------------------------------------------------------------
# Setup

modparams = {
    "boards": (int, 1, "number of boards, 1..4"),
    "loopback": (int, 0, "1: simulate a loopback test rig"),
}


cdef int export_board(board_t *b, int num) noexcept nogil:
    cdef int i, r
    r = rt.device_export(&b.dev, comp_id, b"rtboard", num)
    for i in range(NUM_DIGIN):
        if r == 0:
            r = rt.digin_export(&b.din[i], comp_id, b"rtboard", num, i)
    for i in range(NUM_DIGOUT):
        if r == 0:
            r = rt.digout_export(&b.dout[i], comp_id, b"rtboard", num, i)
    for i in range(NUM_ADCIN):
        if r == 0:
            r = rt.adcin_export(&b.adc[i], comp_id, b"rtboard", num, i)
    for i in range(NUM_DACOUT):
        if r == 0:
            r = rt.dacout_export(&b.dac[i], comp_id, b"rtboard", num, i)
    for i in range(NUM_ENCODER):
        if r == 0:
            r = rt.encoder_export(&b.enc[i], comp_id, b"rtboard", num, i,
                                  ENCODER_BITS, 1)
    if r == 0:
        r = rt.export_funct(board_read, b, comp_id, b"rtboard", num, NULL,
                            b"read")
    if r == 0:
        r = rt.export_funct(board_write, b, comp_id, b"rtboard", num, NULL,
                            b"write")
    return r


def setup(boards=1, loopback=0):
    global comp_id, num_boards
    cdef board_t *b
    cdef int i, r
    if not 1 <= boards <= MAX_BOARDS:
        raise ValueError(f"boards={boards} is not 1..{MAX_BOARDS}")
    if loopback not in (0, 1):
        raise ValueError(f"loopback={loopback} is not 0 or 1")
    comp_id = hal.hal_init(b"rtboard")
    rt.check(comp_id, "hal_init")
    for i in range(boards):
        b = <board_t *>hal.hal_malloc(sizeof(board_t))
        if b == NULL:
            raise MemoryError("hal_malloc failed")
        # "map" the board: a zeroed register block that is ready
        b.regs = <unsigned int *>hal.hal_malloc(NUM_REGS * sizeof(int))
        if b.regs == NULL:
            raise MemoryError("hal_malloc failed")
        for r in range(NUM_REGS):
            b.regs[r] = 0
        b.regs[REG_STATUS] = STATUS_READY
        b.loopback = loopback
        rt.check(export_board(b, i), f"rtboard.{i}")
        board_ptr[i] = b
    num_boards = boards
    rt.check(hal.hal_ready(comp_id), "hal_ready")


def cleanup():
    global comp_id, num_boards
    num_boards = 0
    if comp_id >= 0:
        hal.hal_exit(comp_id)
        comp_id = -1


# ---------------------------------------------------------------------
# The other side of the bus, for tests and simulations (not realtime)

cdef unsigned int *_register(int board, reg) except NULL:
    if not 0 <= board < num_boards:
        raise IndexError(f"rtboard: no board {board} (boards={num_boards})")
    if reg not in REGISTERS:
        raise KeyError(f"rtboard: no register '{reg}' (one of "
                       f"{', '.join(REGISTERS)})")
    return &board_ptr[board].regs[<int>REGISTERS[reg]]


def peek(int board, str reg):
    """Read register ``reg`` (a name of REGISTERS) of a board."""
    return _register(board, reg)[0]


def poke(int board, str reg, value):
    """Write register ``reg`` of a board (taken modulo 2**32)."""
    _register(board, reg)[0] = <unsigned int>(int(value) & 0xffffffff)
