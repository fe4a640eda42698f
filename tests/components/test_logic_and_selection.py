"""The logic and selection components: multiplexers (mux2, mux4, mux8,
mux16, mux_generic), decoders (select8, demux), code converters (bin2gray,
gray2bin), tristate buffers, gates (maj3, match8, logic, lut5) and bit
operations (bitslice, bitwise).

The reference's exact outputs are checked by tests/data/complib/*.hal; these
tests state the rules in Python over many inputs."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import halsdk
from halsdk.core import _core

MS = 1_000_000
RNG = np.random.default_rng(1234)


def thread(hal, *functs, fp=True, period=MS):
    hal.newthread("t", period, fp=fp)
    for f in functs:
        hal.addf(f, "t")


def gray(n: int) -> int:
    return n ^ (n >> 1)


# ---- multiplexers with select bits -----------------------------------------

@pytest.mark.parametrize("comp,bits", [("mux2", 1), ("mux4", 2), ("mux8", 3)])
def test_mux_selects_input_by_binary_number(hal, comp, bits):
    hal.loadrt(comp)
    thread(hal, f"{comp}.0")
    values = RNG.normal(size=2 ** bits) * 1000
    sels = ["sel"] if bits == 1 else [f"sel{k}" for k in range(bits)]
    hal.set({f"{comp}.0.in{k}": v for k, v in enumerate(values)})
    for n in range(2 ** bits):
        hal.set({f"{comp}.0.{s}": bool(n >> k & 1)
                 for k, s in enumerate(sels)})
        hal.step(1)
        assert hal.getp(f"{comp}.0.out") == values[n]
    [f] = hal.functions()
    assert f.uses_fp is True


def test_mux2_follows_moving_input(hal):
    hal.loadrt("mux2")
    thread(hal, "mux2.0")
    tr = hal.run(4, inputs={"mux2.0.in0": [1.0, 2.0, 3.0, 4.0],
                            "mux2.0.in1": -7.5,
                            "mux2.0.sel": [0, 0, 1, 0]},
                 record=["mux2.0.out"])
    assert tr["mux2.0.out"].tolist() == [1.0, 2.0, -7.5, 4.0]


def mux16(hal, **pins):
    hal.loadrt("mux16")
    thread(hal, "mux16.0")
    hal.set({f"mux16.0.in{k:02d}": 100.0 + k for k in range(16)})
    hal.set({f"mux16.0.{k.replace('_', '-')}": v for k, v in pins.items()})


def set_sel16(hal, n):
    hal.set({f"mux16.0.sel{k}": bool(n >> k & 1) for k in range(4)})


def test_mux16_binary_and_gray_code(hal):
    mux16(hal)
    for n in range(16):
        set_sel16(hal, n)
        hal.step(1)
        assert hal.getp("mux16.0.out-f") == 100.0 + n
        assert hal.getp("mux16.0.selected") == n
    hal.setp("mux16.0.use-graycode", True)
    for n in range(16):
        set_sel16(hal, gray(n))        # the switch gives n's Gray code
        hal.step(1)
        assert hal.getp("mux16.0.out-f") == 100.0 + n
        assert hal.getp("mux16.0.out-s") == 100 + n


def test_mux16_out_s_truncates_and_saturates_to_int_min(hal):
    mux16(hal)
    cases = {1: (-2.9, -2), 2: (2.9, 2), 3: (2147483647.9, 2147483647),
             4: (-2147483648.9, -2147483648), 5: (1e10, -2147483648),
             6: (-1e10, -2147483648), 7: (float("nan"), -2147483648)}
    for n, (v, want) in cases.items():
        hal.setp(f"mux16.0.in{n:02d}", v)
        set_sel16(hal, n)
        hal.step(1)
        assert hal.getp("mux16.0.out-s") == want


def test_mux16_suppress_no_input_holds_output(hal):
    mux16(hal, suppress_no_input=True)
    set_sel16(hal, 5)
    hal.step(1)
    set_sel16(hal, 0)
    hal.step(3)
    assert hal.getp("mux16.0.out-f") == 105.0
    hal.setp("mux16.0.suppress-no-input", False)
    hal.step(1)
    assert hal.getp("mux16.0.out-f") == 100.0


def test_mux16_debounce_counts_from_first_change(hal):
    """A selection differing from the current one for debounce-time
    takes over, even if it changed while waiting; elapsed stays at the
    time it took."""
    mux16(hal)
    hal.step(1)                              # in00 selected at once
    hal.setp("mux16.0.debounce-time", 0.0035)
    outs = []
    for n in [3] * 2 + [6] * 4 + [6] * 2:
        set_sel16(hal, n)
        hal.step(1)
        outs.append(hal.getp("mux16.0.out-f"))
    # 3 then 6 from cycle 0: elapsed 1, 2, 3, 4 ms; takes over in cycle 4
    assert outs == [100.0] * 4 + [106.0] * 4
    assert hal.getp("mux16.0.elapsed") == pytest.approx(0.004)
    # back to the current selection before the time is up: no change
    for n in (1, 1, 6, 6, 6, 6, 6):
        set_sel16(hal, n)
        hal.step(1)
        assert hal.getp("mux16.0.out-f") == 106.0


# ---- decoders ---------------------------------------------------------------

def test_select8(hal):
    hal.loadrt("select8")
    thread(hal, "select8.0", fp=False)
    assert hal.getp("select8.0.enable") is True
    for sel in [-1, 0, 1, 5, 7, 8, 2 ** 31 - 1]:
        hal.setp("select8.0.sel", sel)
        hal.step(1)
        got = [hal.getp(f"select8.0.out{k}") for k in range(8)]
        assert got == [k == sel for k in range(8)]
    hal.setp("select8.0.sel", 3)
    hal.setp("select8.0.enable", False)
    hal.step(1)
    assert not any(hal.getp(f"select8.0.out{k}") for k in range(8))


def demux_outs(hal, inst, n):
    return [hal.getp(f"demux.{inst}.out-{k:02d}") for k in range(n)]


def test_demux_selects_clamps_and_bargraph(hal):
    hal.loadrt("demux", "count=2 personality=6,6")
    thread(hal, "demux.0", "demux.1")
    hal.setp("demux.1.bargraph", True)
    assert len(hal.pins("demux.0.out-*")) == 6
    assert len(hal.pins("demux.0.sel-bit-*")) == 5
    for bits, num in [(0, 0), (3, 0), (0, 4), (2, 3), (31, 0), (0, 100),
                      (1, 0xFFFFFFFF), (0, 0xFFFFFFFF), (0, 0x80000000)]:
        hal.set({f"demux.{i}.sel-bit-{k:02d}": bool(bits >> k & 1)
                 for i in (0, 1) for k in range(5)})
        hal.set({"demux.0.sel-u32": num, "demux.1.sel-u32": num})
        hal.step(1)
        s = (bits + num) & 0xFFFFFFFF
        s = s - 2 ** 32 if s >= 2 ** 31 else s       # read as signed
        s = min(s, 5)                                # past the end: last
        assert demux_outs(hal, 0, 6) == [k == s for k in range(6)]
        assert demux_outs(hal, 1, 6) == [k < s for k in range(6)]


def test_demux_default_personality_is_32(hal):
    """As the reference: no personality, or a list shorter than the
    instances, gives 32 outputs."""
    hal.loadrt("demux", "count=3 personality=4")
    assert [len(hal.pins(f"demux.{i}.out-*")) for i in range(3)] == \
        [4, 32, 32]
    thread(hal, "demux.2")
    hal.setp("demux.2.sel-u32", 31)
    hal.step(1)
    assert demux_outs(hal, 2, 32) == [k == 31 for k in range(32)]


def test_demux_too_many_outputs(hal):
    with pytest.raises(halsdk.CapacityError,
                       match="Requested size 33 exceeds max size 32"):
        hal.loadrt("demux", "personality=33")
    assert hal.components("demux") == []


# ---- codes and bits ---------------------------------------------------------

U32 = [0, 1, 2, 3, 255, 256, 0x7FFFFFFF, 0x80000000, 0xFFFFFFFF] + \
    RNG.integers(0, 2 ** 32, 40).tolist()


def test_bin2gray_and_back(hal):
    hal.loadrt("bin2gray")
    hal.loadrt("gray2bin")
    thread(hal, "bin2gray.0", "gray2bin.0", fp=False)
    hal.net("g", "bin2gray.0.out", "gray2bin.0.in")
    for n in U32:
        hal.setp("bin2gray.0.in", n)
        hal.step(1)
        assert hal.getp("bin2gray.0.out") == gray(n)
        assert hal.getp("gray2bin.0.out") == n


def test_gray_codes_of_neighbours_differ_in_one_bit(hal):
    hal.loadrt("bin2gray")
    thread(hal, "bin2gray.0", fp=False)
    tr = hal.run(300, inputs={"bin2gray.0.in": np.arange(300)},
                 record=["bin2gray.0.out"])
    codes = tr["bin2gray.0.out"].astype(np.int64)
    assert all(bin(int(x)).count("1") == 1 for x in codes[1:] ^ codes[:-1])


def test_bitwise(hal):
    hal.loadrt("bitwise")
    thread(hal, "bitwise.0", fp=False)
    m = 0xFFFFFFFF
    for a, b in zip(U32, reversed(U32)):
        hal.set({"bitwise.0.in0": a, "bitwise.0.in1": b})
        hal.step(1)
        want = {"and": a & b, "or": a | b, "xor": a ^ b,
                "nand": ~(a & b) & m, "nor": ~(a | b) & m,
                "xnor": ~(a ^ b) & m}
        for op, v in want.items():
            assert hal.getp(f"bitwise.0.out-{op}") == v, op


def test_bitslice(hal):
    hal.loadrt("bitslice", "count=3 personality=32,5")
    thread(hal, "bitslice.0", "bitslice.1", "bitslice.2", fp=False)
    assert len(hal.pins("bitslice.1.out-*")) == 5
    assert hal.pins("bitslice.2.out-*") == []    # no personality: no bits
    for n in U32:
        for i in (0, 1, 2):
            hal.setp(f"bitslice.{i}.in", n)
        hal.step(1)
        assert [hal.getp(f"bitslice.0.out-{k:02d}") for k in range(32)] == \
            [bool(n >> k & 1) for k in range(32)]
        assert [hal.getp(f"bitslice.1.out-{k:02d}") for k in range(5)] == \
            [bool(n >> k & 1) for k in range(5)]


def test_bitslice_too_many_bits(hal):
    with pytest.raises(halsdk.CapacityError, match="max size 32"):
        hal.loadrt("bitslice", "names=x personality=40")
    assert hal.components("bitslice") == []


# ---- tristate buffers -------------------------------------------------------

@pytest.mark.parametrize("kind,a,b", [("bit", True, False),
                                      ("float", 2.5, -1.0)])
def test_tristate_shares_a_signal(hal, kind, a, b):
    hal.loadrt(f"tristate_{kind}", count=2)
    thread(hal, f"tristate-{kind}.0", f"tristate-{kind}.1",
           fp=kind == "float")
    assert hal.pin(f"tristate-{kind}.0.out").direction == _core.IO
    hal.net("bus", f"tristate-{kind}.0.out", f"tristate-{kind}.1.out")
    hal.set({f"tristate-{kind}.0.in": a, f"tristate-{kind}.1.in": b})
    hal.setp(f"tristate-{kind}.0.enable", True)
    hal.step(1)
    assert hal.getp(f"tristate-{kind}.1.out") == a
    hal.setp(f"tristate-{kind}.0.enable", False)
    hal.step(2)
    # nobody drives the signal now: it keeps its value
    assert hal.getp(f"tristate-{kind}.1.out") == a
    hal.setp(f"tristate-{kind}.1.enable", True)
    hal.step(1)
    assert hal.getp(f"tristate-{kind}.1.out") == b


def test_tristate_names_keep_underscores(hal):
    hal.loadrt("tristate_bit", names="my_buf")
    assert [f.name for f in hal.functions()] == ["my_buf"]


# ---- gates ------------------------------------------------------------------

def test_maj3(hal):
    hal.loadrt("maj3", count=2)
    thread(hal, "maj3.0", "maj3.1", fp=False)
    hal.setp("maj3.1.invert", True)
    for ins in itertools.product((False, True), repeat=3):
        hal.set({f"maj3.{i}.in{k + 1}": v for i in (0, 1)
                 for k, v in enumerate(ins)})
        hal.step(1)
        assert hal.getp("maj3.0.out") is (sum(ins) >= 2)
        assert hal.getp("maj3.1.out") is (sum(ins) < 2)


def test_match8(hal):
    hal.loadrt("match8")
    thread(hal, "match8.0", fp=False)
    assert hal.getp("match8.0.in") is True
    pairs = [(n, n) for n in RNG.integers(0, 256, 10).tolist()]
    pairs += [(n, n ^ (1 << k)) for k, n in enumerate(range(8))]
    for a, b in pairs:
        hal.set({f"match8.0.a{k}": bool(a >> k & 1) for k in range(8)})
        hal.set({f"match8.0.b{k}": bool(b >> k & 1) for k in range(8)})
        hal.setp("match8.0.in", True)
        hal.step(1)
        assert hal.getp("match8.0.out") is (a == b)
        hal.setp("match8.0.in", False)
        hal.step(1)
        assert hal.getp("match8.0.out") is False


LOGIC_OUTS = {0x100: ("and", lambda n, k: k == n),
              0x200: ("or", lambda n, k: k > 0),
              0x400: ("xor", lambda n, k: k % 2 == 1),
              0x800: ("nand", lambda n, k: k != n),
              0x1000: ("nor", lambda n, k: k == 0)}


@pytest.mark.parametrize("n_in", [0, 1, 2, 5, 16])
def test_logic_all_outputs(hal, n_in):
    hal.loadrt("logic", f"personality={0x1f00 + n_in:#x}")
    thread(hal, "logic.0", fp=False)
    assert len(hal.pins("logic.0.in-*")) == n_in
    patterns = RNG.integers(0, 2, (40, n_in)).astype(bool)
    for ins in patterns:
        hal.set({f"logic.0.in-{k:02d}": bool(v) for k, v in enumerate(ins)})
        hal.step(1)
        for name, rule in LOGIC_OUTS.values():
            assert hal.getp(f"logic.0.{name}") is rule(n_in, int(ins.sum()))


def test_logic_personality_chooses_pins(hal):
    hal.loadrt("logic", "names=g1,g2 personality=0x402,0x1803")
    assert [p.name for p in hal.pins("g1.*")] == [
        "g1.in-00", "g1.in-01", "g1.time", "g1.xor"]
    assert [p.name for p in hal.pins("g2.*")] == [
        "g2.in-00", "g2.in-01", "g2.in-02", "g2.nand", "g2.nor", "g2.time"]


def test_logic_too_many_inputs(hal):
    with pytest.raises(halsdk.CapacityError,
                       match="Pin in-##: Requested size 17 exceeds max size"):
        hal.loadrt("logic", "names=g3 personality=0x111")
    assert hal.components("logic") == [] and hal.pins() == []


def test_lut5_truth_table(hal):
    hal.loadrt("lut5", count=3)
    thread(hal, "lut5.0", "lut5.1", "lut5.2", fp=False)
    funcs = [0x80000000, 0xFFFFFFFE, int(RNG.integers(0, 2 ** 32))]
    for i, f in enumerate(funcs):
        hal.setp(f"lut5.{i}.function", f)
    for row in range(32):
        hal.set({f"lut5.{i}.in-{k}": bool(row >> k & 1)
                 for i in range(3) for k in range(5)})
        hal.step(1)
        for i, f in enumerate(funcs):
            assert hal.getp(f"lut5.{i}.out") is bool(f >> row & 1)


# ---- mux_generic ------------------------------------------------------------

def test_mux_generic_pins_and_threads(hal):
    hal.loadrt("mux_generic", "config=bb2,uf7,SU8,bu1500")
    fns = {f.name: f.uses_fp for f in hal.functions()}
    assert fns == {"mux-gen.00": False, "mux-gen.01": True,
                   "mux-gen.02": False, "mux-gen.03": False}
    assert len(hal.pins("mux-gen.01.in-u32-*")) == 7
    assert hal.pin("mux-gen.01.out-float").type == _core.FLOAT
    assert len(hal.pins("mux-gen.01.sel-bit-*")) == 2
    assert len(hal.pins("mux-gen.02.sel-bit-*")) == 3
    assert len(hal.pins("mux-gen.03.in-bit-*")) == 1024
    assert len(hal.pins("mux-gen.03.sel-bit-*")) == 10
    assert hal.param("mux-gen.00.elapsed").type == _core.U32


@pytest.mark.parametrize("config,exc,msg", [
    (None, halsdk.InvalidError, "requires at least one valid format"),
    ("bb1", halsdk.NotPermittedError, "one-element mux makes no sense"),
    ("bb4,bx4", halsdk.NotPermittedError, "invalid character"),
    ("bfs4", halsdk.NotPermittedError, "too many type specifiers"),
    ("bb4,4", halsdk.NotPermittedError, "No type specifiers"),
    ("ff", halsdk.NotPermittedError, "No entry count given"),
    ("bb2,,ff2", halsdk.NotPermittedError, "No entry count given"),
])
def test_mux_generic_refuses_bad_config(hal, config, exc, msg):
    with pytest.raises(exc, match=msg):
        hal.loadrt("mux_generic", f"config={config}" if config else "")
    assert hal.components("mux_generic") == [] and hal.pins() == []


def test_mux_generic_conversions(hal):
    hal.loadrt("mux_generic", "config=fs4,fu4,fb4,us2,su2,sf2,bu2")
    thread(hal, *[f"mux-gen.{k:02d}" for k in range(7)])
    cases = {
        "00": ("float", "s32", [1e10, -2.7, 2.9, -1e10],
               [2147483647, -2, 2, -2147483647]),
        "01": ("float", "u32", [-1.5, 4294967295.9, 5e9, 3.99],
               [0, 4294967295, 4294967295, 3]),
        "02": ("float", "bit", [0.0, -0.0, -2.0, 0.4],
               [False, False, True, True]),
        "03": ("u32", "s32", [4294967295, 12], [2147483647, 12]),
        "04": ("s32", "u32", [-1, 7], [0, 7]),
        "05": ("s32", "float", [-2147483648, 5], [-2147483648.0, 5.0]),
        "06": ("bit", "u32", [False, True], [0, 1]),
    }
    for k, (ti, _, ins, _) in cases.items():
        hal.set({f"mux-gen.{k}.in-{ti}-{i:02d}": v
                 for i, v in enumerate(ins)})
    for i in range(4):
        for k in cases:
            hal.setp(f"mux-gen.{k}.sel-int", i)
        hal.step(1)
        for k, (_, to, ins, want) in cases.items():
            if i < len(ins):
                assert hal.getp(f"mux-gen.{k}.out-{to}") == want[i], k


def test_mux_generic_selection_and_debounce(hal):
    hal.loadrt("mux_generic", "config=uu8")
    thread(hal, "mux-gen.00", fp=False)
    hal.set({f"mux-gen.00.in-u32-{i:02d}": 10 + i for i in range(8)})

    def sel(bits, num=0, cycles=1):
        hal.set({f"mux-gen.00.sel-bit-{k:02d}": bool(bits >> k & 1)
                 for k in range(3)})
        hal.setp("mux-gen.00.sel-int", num)
        out = []
        for _ in range(cycles):
            hal.step(1)
            out.append(hal.getp("mux-gen.00.out-u32"))
        return out

    assert sel(5) == [15]
    assert sel(2, 3) == [15]                 # bits and number add up
    assert sel(7, 100) == [17]               # past the end: the last
    hal.setp("mux-gen.00.suppress-no-input", True)
    assert sel(0, 0, 3) == [17] * 3          # 0 suppressed
    assert sel(0, 2) == [12]                 # only the sum counts
    hal.setp("mux-gen.00.suppress-no-input", False)
    hal.setp("mux-gen.00.debounce-us", 2500)
    assert sel(1, 0, 2) == [12, 12]
    assert hal.getp("mux-gen.00.elapsed") == 2000   # microseconds
    assert sel(4, 0, 3) == [12, 14, 14]      # the wait went on
    assert hal.getp("mux-gen.00.elapsed") == 0
    assert hal.getp("mux-gen.00.selected") == 4
    assert sel(6, 0, 2) == [14, 14]
    assert sel(4) == [14]                    # back: the wait starts over
    assert sel(6, 0, 4) == [14, 14, 14, 16]
