"""Property tests of the simple components: whatever the inputs and
parameters, the outputs keep the component's promise (a limit holds, a
count matches the edges, an output stays between its inputs...).  Each
test drives one instance through the stepped Python API, as
test_limit3_properties.py does for limit3."""

from __future__ import annotations

import numpy as np
from helpers.components import setup
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

N = 50
SETTINGS = settings(max_examples=25, deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])

finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)
signal = st.lists(finite, min_size=N, max_size=N)
bits = st.lists(st.booleans(), min_size=N, max_size=N)


def once(hal, comp, funct, args=()):
    """Load ``comp`` the first time a test's examples run."""
    if not hal.components(comp):
        setup(hal, comp, funct, args=args)


@SETTINGS
@given(x=signal, a=finite, b=finite)
def test_limit1_stays_within(hal, x, a, b):
    once(hal, "limit1", "limit1.0")
    lo, hi = min(a, b), max(a, b)
    hal.set({"limit1.0.min": lo, "limit1.0.max": hi})
    out = hal.run(N, inputs={"limit1.0.in": np.array(x)},
                  record=["limit1.0.out"])["limit1.0.out"]
    assert out.min() >= lo and out.max() <= hi
    assert (out == np.clip(x, lo, hi)).all()


@SETTINGS
@given(x=signal, a=finite, b=finite, maxv=st.floats(1.0, 1e7))
def test_limit2_stays_within_and_under_maxv(hal, x, a, b, maxv):
    once(hal, "limit2", "limit2.0")
    lo, hi = min(a, b), max(a, b)
    hal.set({"limit2.0.min": lo, "limit2.0.max": hi,
             "limit2.0.maxv": maxv, "limit2.0.in": lo,
             "limit2.0.load": True})
    hal.step(1)
    hal.setp("limit2.0.load", False)
    out = hal.run(N, inputs={"limit2.0.in": np.array(x)},
                  record=["limit2.0.out"])["limit2.0.out"]
    out = np.concatenate([[lo], out])
    assert out.min() >= lo and out.max() <= hi
    step = np.abs(np.diff(out))
    assert step.max() <= maxv * 1e-3 * (1 + 1e-9) + 1e-9 * max(abs(lo),
                                                                abs(hi))


@SETTINGS
@given(x=signal, gain=st.floats(0.0, 1.0))
def test_lowpass_moves_between_old_output_and_input(hal, x, gain):
    once(hal, "lowpass", "lowpass.0")
    hal.set({"lowpass.0.gain": gain, "lowpass.0.in": 0.0,
             "lowpass.0.load": True})
    hal.step(1)
    hal.setp("lowpass.0.load", False)
    out = hal.run(N, inputs={"lowpass.0.in": np.array(x)},
                  record=["lowpass.0.out"])["lowpass.0.out"]
    old = np.concatenate([[0.0], out[:-1]])
    lo, hi = np.minimum(old, x), np.maximum(old, x)
    tol = 1e-9 * np.maximum(np.abs(lo), np.abs(hi))
    assert (out >= lo - tol).all() and (out <= hi + tol).all()


@SETTINGS
@given(x=signal, a=finite, b=finite)
def test_wcomp_window(hal, x, a, b):
    once(hal, "wcomp", "wcomp.0")
    lo, hi = min(a, b), max(a, b)
    hal.set({"wcomp.0.min": lo, "wcomp.0.max": hi})
    tr = hal.run(N, inputs={"wcomp.0.in": np.array(x)},
                 record=["wcomp.0.out", "wcomp.0.over", "wcomp.0.under"])
    x = np.array(x)
    assert (tr["wcomp.0.out"] == ((x > lo) & (x < hi))).all()
    assert (tr["wcomp.0.over"] == (x >= hi)).all()
    assert (tr["wcomp.0.under"] == (x <= lo)).all()


@SETTINGS
@given(x=signal, center=finite, threshold=st.floats(0.0, 1e6))
def test_deadzone_zero_inside_and_shifted_outside(hal, x, center,
                                                  threshold):
    once(hal, "deadzone", "deadzone.0")
    hal.set({"deadzone.0.center": center,
             "deadzone.0.threshold": threshold})
    out = hal.run(N, inputs={"deadzone.0.in": np.array(x)},
                  record=["deadzone.0.out"])["deadzone.0.out"]
    d = np.array(x) - center
    half = threshold / 2
    inside = np.abs(d) <= half
    assert (out[inside] == center).all()
    # outside: moved towards the center by half the band, never across
    e = out[~inside] - center
    assert (np.sign(e) == np.sign(d[~inside])).all()
    assert np.allclose(np.abs(e), np.abs(d[~inside]) - half,
                       rtol=1e-9, atol=1e-6)


@SETTINGS
@given(x=signal, reset=bits)
def test_minmax_tracks_extremes_since_reset(hal, x, reset):
    once(hal, "minmax", "minmax.0")
    hal.setp("minmax.0.reset", True)
    hal.setp("minmax.0.in", x[0])
    hal.step(1)
    tr = hal.run(N, inputs={"minmax.0.in": np.array(x),
                            "minmax.0.reset": np.array(reset)},
                 record=["minmax.0.min", "minmax.0.max"])
    lo = hi = x[0]
    for k in range(N):
        if reset[k]:
            lo = hi = x[k]
        lo, hi = min(lo, x[k]), max(hi, x[k])
        assert tr["minmax.0.min"][k] == lo and tr["minmax.0.max"][k] == hi


@SETTINGS
@given(x=signal, hold=bits)
def test_sample_hold_holds(hal, x, hold):
    once(hal, "sample_hold", "sample-hold.0")
    tr = hal.run(N, inputs={"sample-hold.0.in": np.array(x).round(),
                            "sample-hold.0.hold": np.array(hold)},
                 record=["sample-hold.0.out"])["sample-hold.0.out"]
    prev = None
    for k in range(N):
        if hold[k]:
            if prev is not None:
                assert tr[k] == prev
        else:
            assert tr[k] == round(x[k])
        prev = tr[k]


@SETTINGS
@given(x=signal, gain=st.floats(-1e3, 1e3), offset=finite)
def test_scale_is_affine(hal, x, gain, offset):
    once(hal, "scale", "scale.0")
    hal.set({"scale.0.gain": gain, "scale.0.offset": offset})
    out = hal.run(N, inputs={"scale.0.in": np.array(x)},
                  record=["scale.0.out"])["scale.0.out"]
    assert np.allclose(out, np.array(x) * gain + offset, rtol=1e-12,
                       atol=1e-6)


@SETTINGS
@given(ins=st.lists(signal, min_size=4, max_size=4),
       sel=st.lists(st.integers(0, 3), min_size=N, max_size=N))
def test_mux4_out_is_the_selected_input(hal, ins, sel):
    once(hal, "mux4", "mux4.0")
    s = np.array(sel)
    inputs = {f"mux4.0.in{k}": np.array(ins[k]) for k in range(4)}
    inputs.update({"mux4.0.sel0": (s & 1) == 1, "mux4.0.sel1": s >= 2})
    out = hal.run(N, inputs=inputs, record=["mux4.0.out"])["mux4.0.out"]
    assert (out == np.array(ins)[s, np.arange(N)]).all()


@SETTINGS
@given(sel=st.lists(st.integers(-3, 11), min_size=N, max_size=N),
       enable=bits)
def test_select8_one_hot(hal, sel, enable):
    once(hal, "select8", "select8.0")
    names = [f"select8.0.out{k}" for k in range(8)]
    tr = hal.run(N, inputs={"select8.0.sel": np.array(sel),
                            "select8.0.enable": np.array(enable)},
                 record=names)
    outs = np.array([tr[n] for n in names])
    for k in range(N):
        want = np.zeros(8, bool)
        if enable[k] and 0 <= sel[k] < 8:
            want[sel[k]] = True
        assert (outs[:, k] == want).all()


@SETTINGS
@given(words=st.lists(st.integers(0, 2**32 - 1), min_size=N, max_size=N))
def test_bitslice_reconstructs_the_input(hal, words):
    once(hal, "bitslice", "bitslice.0", args=("personality=32",))
    names = [f"bitslice.0.out-{k:02d}" for k in range(32)]
    tr = hal.run(N, inputs={"bitslice.0.in": np.array(words, np.uint64)},
                 record=names)
    back = sum(tr[n].astype(np.uint64) << np.uint64(k)
               for k, n in enumerate(names))
    assert (back == np.array(words, np.uint64)).all()


@SETTINGS
@given(up=bits, down=bits, a=st.integers(-20, 20), b=st.integers(-20, 20),
       clamp=st.booleans())
def test_updown_counts_edges_within_limits(hal, up, down, a, b, clamp):
    once(hal, "updown", "updown.0")
    lo, hi = min(a, b), max(a, b)
    hal.set({"updown.0.min": lo, "updown.0.max": hi,
             "updown.0.clamp": clamp, "updown.0.wrap": False,
             "updown.0.countup": False, "updown.0.countdown": False,
             "updown.0.reset": True})
    hal.step(1)
    hal.setp("updown.0.reset", False)
    count = hal.run(N, inputs={"updown.0.countup": np.array(up),
                               "updown.0.countdown": np.array(down)},
                    record=["updown.0.count"])["updown.0.count"]
    u = np.diff(np.concatenate([[0], np.array(up, int)])) == 1
    d = np.diff(np.concatenate([[0], np.array(down, int)])) == 1
    if clamp:
        assert count.min() >= lo and count.max() <= hi
    else:
        assert (count == np.cumsum(u.astype(int) - d)).all()


@settings(max_examples=30, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(moves=st.lists(st.sampled_from([-1, 0, 1]), min_size=N, max_size=N),
       x4=st.booleans())
def test_encoder_counts_match_quadrature_edges(hal, moves, x4):
    if not hal.components("encoder"):
        hal.loadrt("encoder")
        hal.newthread("t", 1_000_000)
        hal.addf("encoder.update-counters", "t")
        hal.addf("encoder.capture-position", "t")
    hal.set({"encoder.0.x4-mode": x4, "encoder.0.phase-A": False,
             "encoder.0.phase-B": False, "encoder.0.reset": True})
    hal.step(2)
    hal.setp("encoder.0.reset", False)
    # Gray code states 00 10 11 01: +1 per step forward
    gray = [(0, 0), (1, 0), (1, 1), (0, 1)]
    state = np.cumsum(moves)
    a = np.array([gray[s % 4][0] for s in state], bool)
    b = np.array([gray[s % 4][1] for s in state], bool)
    raw0 = hal.getp("encoder.0.rawcounts")
    tr = hal.run(N, inputs={"encoder.0.phase-A": a, "encoder.0.phase-B": b},
                 record=["encoder.0.rawcounts", "encoder.0.counts"])
    raw = tr["encoder.0.rawcounts"] - raw0
    if x4:
        # one count per edge
        assert (raw == state).all()
    else:
        # one count per full cycle of the phases, either way
        assert (np.abs(raw - state / 4) <= 1).all()


@SETTINGS
@given(ins=st.lists(signal, min_size=8, max_size=8),
       sel=st.lists(st.integers(0, 7), min_size=N, max_size=N))
def test_mux8_out_is_the_selected_input(hal, ins, sel):
    once(hal, "mux8", "mux8.0")
    s = np.array(sel)
    inputs = {f"mux8.0.in{k}": np.array(ins[k]) for k in range(8)}
    inputs.update({f"mux8.0.sel{b}": (s >> b) & 1 == 1 for b in range(3)})
    out = hal.run(N, inputs=inputs, record=["mux8.0.out"])["mux8.0.out"]
    assert (out == np.array(ins)[s, np.arange(N)]).all()


@SETTINGS
@given(base=finite, step=finite,
       sel=st.lists(st.integers(0, 15), min_size=N, max_size=N))
def test_mux16_out_is_the_selected_input(hal, base, step, sel):
    once(hal, "mux16", "mux16.0")
    hal.set({"mux16.0.use-graycode": False, "mux16.0.debounce-time": 0.0})
    # sixteen different inputs (hypothesis chokes on 16 lists of N)
    ins = base + np.arange(16)[:, None] * 1000.0 + np.arange(N) * step
    s = np.array(sel)
    inputs = {f"mux16.0.in{k:02d}": ins[k] for k in range(16)}
    inputs.update({f"mux16.0.sel{b}": (s >> b) & 1 == 1 for b in range(4)})
    tr = hal.run(N, inputs=inputs, record=["mux16.0.out-f"])
    assert (tr["mux16.0.out-f"] == ins[s, np.arange(N)]).all()


@SETTINGS
@given(a=bits, b=bits)
def test_not_or2_xor2_truth_tables(hal, a, b):
    if not hal.components("not"):
        for comp in ("not", "or2", "xor2"):
            hal.loadrt(comp)
        hal.newthread("t", 1_000_000)
        for f in ("not.0", "or2.0", "xor2.0"):
            hal.addf(f, "t")
    x, y = np.array(a), np.array(b)
    tr = hal.run(N, inputs={"not.0.in": x, "or2.0.in0": x, "or2.0.in1": y,
                            "xor2.0.in0": x, "xor2.0.in1": y},
                 record=["not.0.out", "or2.0.out", "xor2.0.out"])
    assert (tr["not.0.out"] == ~x).all()
    assert (tr["or2.0.out"] == (x | y)).all()
    assert (tr["xor2.0.out"] == (x ^ y)).all()


@SETTINGS
@given(ins=st.lists(bits, min_size=4, max_size=4),
       weights=st.lists(st.integers(-2**20, 2**20), min_size=4, max_size=4),
       offset=st.integers(-2**20, 2**20))
def test_weighted_sum_is_offset_plus_true_weights(hal, ins, weights, offset):
    once(hal, "weighted_sum", "process_wsums", args=("wsum_sizes=4",))
    hal.set({f"wsum.0.bit.{k}.weight": weights[k] for k in range(4)})
    hal.set({"wsum.0.offset": offset, "wsum.0.hold": False})
    x = np.array(ins)
    tr = hal.run(N, inputs={f"wsum.0.bit.{k}.in": x[k] for k in range(4)},
                 record=["wsum.0.sum"])
    assert (tr["wsum.0.sum"] == offset + np.array(weights) @ x).all()


def _debounced(x, on, off):
    """out follows x once x has differed from it for on (rising) or off
    (falling) cycles in a row."""
    out, run, res = False, 0, []
    for v in x:
        run = run + 1 if v != out else 0
        if run and run >= (on if v else off):
            out, run = bool(v), 0
        res.append(out)
    return np.array(res)


@SETTINGS
@given(x=bits, on=st.integers(1, 6), off=st.integers(1, 6))
def test_timedelay_switches_after_whole_cycles(hal, x, on, off):
    once(hal, "timedelay", "timedelay.0")
    # half a period short: no rounding doubt about the cycle count
    hal.set({"timedelay.0.on-delay": (on - 0.5) * 1e-3,
             "timedelay.0.off-delay": (off - 0.5) * 1e-3,
             "timedelay.0.in": False})
    hal.step(max(on, off) + 2)      # back to out FALSE, timer 0
    out = hal.run(N, inputs={"timedelay.0.in": np.array(x)},
                  record=["timedelay.0.out"])["timedelay.0.out"]
    assert (out == _debounced(x, on, off)).all()


@SETTINGS
@given(x=bits, w=st.integers(1, 8))
def test_oneshot_pulse_is_width_cycles_after_each_edge(hal, x, w):
    once(hal, "oneshot", "oneshot.0")
    hal.set({"oneshot.0.width": (w - 0.5) * 1e-3, "oneshot.0.in": False,
             "oneshot.0.reset": True})
    hal.step(1)
    hal.setp("oneshot.0.reset", False)
    tr = hal.run(N, inputs={"oneshot.0.in": np.array(x)},
                 record=["oneshot.0.out", "oneshot.0.out-not"])
    xi = np.array(x, int)
    edge = np.diff(np.concatenate([[0], xi])) == 1
    # retriggerable: TRUE while an edge is less than w cycles old
    want = np.array([edge[max(0, t - w + 1):t + 1].any() for t in range(N)])
    assert (tr["oneshot.0.out"] == want).all()
    assert (tr["oneshot.0.out-not"] == ~want).all()


@SETTINGS
@given(angle=st.floats(-1e4, 1e4), position=st.floats(-1e4, 1e4),
       mode=st.integers(0, 2))
def test_orient_command_is_the_angle_on_the_side_the_mode_asks(
        hal, angle, position, mode):
    once(hal, "orient", "orient.0")
    hal.set({"orient.0.enable": False, "orient.0.angle": angle,
             "orient.0.position": position, "orient.0.mode": mode})
    hal.step(1)
    hal.setp("orient.0.enable", True)
    hal.step(1)
    command = hal.getp("orient.0.command")
    ahead = command - position
    # the target angle plus whole revolutions
    revs = command - angle / 360.0
    assert abs(revs - round(revs)) < 1e-9
    eps = 1e-9
    if mode == 0:
        assert -0.5 - eps < ahead <= 0.5 + eps
    elif mode == 1:
        assert -eps <= ahead < 1 + eps
    else:
        assert -1 - eps < ahead <= eps


@SETTINGS
@given(x=bits, pt=st.sampled_from([float("nan"), float("inf")]))
def test_ton_never_reaches_a_nan_or_infinite_pt(hal, x, pt):
    once(hal, "ton", "ton.0")
    hal.set({"ton.0.pt": pt, "ton.0.in": False})
    hal.step(1)                     # et back to 0
    tr = hal.run(N, inputs={"ton.0.in": np.array(x)},
                 record=["ton.0.q", "ton.0.et"])
    assert not tr["ton.0.q"].any()
    # et counts the periods since in went TRUE
    run = 0
    for k, v in enumerate(x):
        run = run + 1 if v else 0
        assert abs(tr["ton.0.et"][k] - run * 1e-3) < 1e-9


@SETTINGS
@given(en=bits, x=bits, k=st.integers(1, 4))
def test_watchdog_ok_only_while_enabled_and_in_time(hal, en, x, k):
    if not hal.components("watchdog"):
        setup(hal, "watchdog", "watchdog.process", "watchdog.set-timeouts",
              args=("num_inputs=1",))
    hal.set({"watchdog.timeout-0": (k - 0.5) * 1e-3,
             "watchdog.enable-in": False})
    hal.step(1)
    tr = hal.run(N, inputs={"watchdog.enable-in": np.array(en),
                            "watchdog.input-0": np.array(x)},
                 record=["watchdog.ok-out"])
    ok = tr["watchdog.ok-out"]
    for t in range(N):
        if not en[t]:
            assert not ok[t]
        elif ok[t] and not (t == 0 or not en[t - 1]):
            # ok-out turns TRUE only at a rising edge of enable-in
            assert ok[t - 1]


@SETTINGS
@given(amp=finite, off=finite, freq=st.floats(0.0, 499.0))
def test_siggen_waves_share_one_phase(hal, amp, off, freq):
    # (a negative frequency runs the phase below 0 without end, as in the
    # reference: the waves then leave their range)
    once(hal, "siggen", "siggen.0.update")
    hal.set({"siggen.0.amplitude": amp, "siggen.0.offset": off,
             "siggen.0.frequency": freq, "siggen.0.reset": True})
    hal.step(1)
    hal.setp("siggen.0.reset", False)
    tr = hal.run(N, record=["siggen.0.sawtooth", "siggen.0.triangle",
                            "siggen.0.square", "siggen.0.clock"])
    # the sawtooth gives the phase; the triangle folds it, the square and
    # the clock split it at one half
    s = (tr["siggen.0.sawtooth"] - off) / amp if amp else None
    tol = 1e-6 * (abs(amp) + abs(off)) + 1e-9
    if s is not None:
        assert (np.abs(s) <= 1 + 1e-6).all()
        tri = amp * (2 * np.abs(s) - 1) + off
        assert np.allclose(tr["siggen.0.triangle"], tri, rtol=0, atol=tol)
        high = s > 0
        sure = np.abs(s) > 1e-6
        assert (tr["siggen.0.clock"][sure] == high[sure]).all()
    sq = np.where(tr["siggen.0.clock"], amp + off, off - amp)
    assert np.allclose(tr["siggen.0.square"], sq, rtol=0, atol=tol)


def _steps_made(tr, step_type):
    """The signed number of steps in the recorded outputs of stepgen.0."""
    def rises(x):
        x = np.asarray(x, int)
        return np.diff(np.concatenate([[0], x])) == 1
    if step_type == 0:
        up = rises(tr["stepgen.0.step"])
        back = np.asarray(tr["stepgen.0.dir"], bool)
        return int(up[~back].sum()) - int(up[back].sum())
    if step_type == 1:
        return int(rises(tr["stepgen.0.up"]).sum()
                   - rises(tr["stepgen.0.down"]).sum())
    # quadrature: the Gray code A/B moves one state a step
    a = np.asarray(tr["stepgen.0.phase-A"], int)
    b = np.asarray(tr["stepgen.0.phase-B"], int)
    state = np.array([0, 1, 3, 2])[a * 2 + b]
    d = np.diff(np.concatenate([[state[0]], state])) % 4
    assert not (d == 2).any()
    return int((d == 3).sum()) - int((d == 1).sum())


@settings(max_examples=8, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(step_type=st.sampled_from([0, 1, 2]),
       scale=st.floats(10.0, 500.0),
       vel=st.floats(1000.0, 4000.0), acc=st.floats(5e4, 2e5),
       targets=st.lists(st.integers(-60, 60), min_size=1, max_size=2),
       frac=st.floats(-0.4, 0.4))
def test_stepgen_steps_match_position_times_scale(hal, step_type, scale, vel,
                                                  acc, targets, frac):
    """Position mode: once the command has been still long enough to be
    reached within maxvel and maxaccel, the steps made (counted on the
    step outputs) are position-cmd * position-scale within one step."""
    base, servo = 50_000, 1_000_000
    hal.loadrt("stepgen", f"step_type={step_type}")
    try:
        hal.newthread("base", base, fp=False)
        hal.newthread("servo", servo)
        _stepgen_moves(hal, step_type, scale, vel, acc, targets, frac, base)
    finally:
        hal.unloadrt("stepgen")
        for t in ("base", "servo"):
            if hal.threads(t):
                hal.delthread(t)


def _stepgen_moves(hal, step_type, scale, vel, acc, targets, frac, base):
    hal.addf("stepgen.make-pulses", "base")
    hal.addf("stepgen.update-freq", "servo")
    hal.addf("stepgen.capture-position", "servo")
    # vel and acc in steps/s and steps/s^2, the limits in machine units
    hal.set({"stepgen.0.position-scale": scale,
             "stepgen.0.maxvel": vel / scale,
             "stepgen.0.maxaccel": acc / scale,
             "stepgen.0.enable": True})
    here = 0.0
    for t in targets:
        goal = t + frac
        d = abs(goal - here)
        settle = vel / acc + d / vel + 2 * (d / acc) ** 0.5 + 0.01
        n = int(settle * 1e9 / base) + 1
        hal.setp("stepgen.0.position-cmd", goal / scale)
        rec = {0: ["stepgen.0.step", "stepgen.0.dir"],
               1: ["stepgen.0.up", "stepgen.0.down"],
               2: ["stepgen.0.phase-A", "stepgen.0.phase-B"]}[step_type]
        tr = hal.run(n, record=rec)
        here += _steps_made(tr, step_type)
        assert abs(here - goal) <= 1.0, (here, goal)


@SETTINGS
@given(cmd=signal, fb=signal, en=bits, maxout=finite,
       gains=st.lists(st.floats(-100, 100), min_size=3, max_size=3))
def test_pid_output_within_maxoutput_and_zero_when_disabled(
        hal, cmd, fb, en, maxout, gains):
    once(hal, "pid", "pid.0.do-pid-calcs", args=("num_chan=1",))
    hal.set({"pid.0.Pgain": gains[0], "pid.0.Igain": gains[1],
             "pid.0.FF1": gains[2], "pid.0.maxoutput": maxout})
    tr = hal.run(N, inputs={"pid.0.command": np.array(cmd),
                            "pid.0.feedback": np.array(fb),
                            "pid.0.enable": np.array(en)},
                 record=["pid.0.output", "pid.0.saturated"])
    on = np.array(en)
    out = tr["pid.0.output"]
    # disabled: 0 and not saturated, even with a negative maxoutput
    assert (out[~on] == 0).all() and not tr["pid.0.saturated"][~on].any()
    if maxout != 0:
        assert (np.abs(out[on]) <= abs(maxout)).all()


# values with NaN, infinities and exact ties, as the fuzzer drives them
edgy = st.sampled_from([0.0, -0.0, 0.5, 1.0, -1.0, 2.0, 1e300, -1e300,
                        float("inf"), float("-inf"), float("nan")]) | finite


@SETTINGS
@given(pos=st.lists(edgy, min_size=N, max_size=N), home=edgy, hyst=edgy,
       maxlo=edgy, maxup=edgy, minlo=edgy, minup=edgy, offset=edgy,
       homing=bits)
def test_sim_axis_hardware_switches(hal, pos, home, hyst, maxlo, maxup,
                                    minlo, minup, offset, homing):
    """Each switch is TRUE unless a comparison puts the position outside:
    a NaN anywhere turns it on, a position on a bound leaves a limit
    switch off (as the reference)."""
    once(hal, "sim_axis_hardware", "sim-axis-hardware.0.update")
    j = "sim-axis-hardware.0.X"
    hal.set({j + "homesw-pos": home, j + "homesw-hyst": hyst,
             j + "maxsw-lower": maxlo, j + "maxsw-upper": maxup,
             j + "minsw-lower": minlo, j + "minsw-upper": minup,
             "sim-axis-hardware.0.limit-offset": offset})
    outs = ["homesw-out", "maxsw-out", "minsw-out", "bothsw-out",
            "bothsw-homesw-out"]
    p = np.array(pos)
    h = np.array(homing)
    with np.errstate(invalid="ignore", over="ignore"):
        d = p - home
        exp_home = ~(d < -hyst * 0.5) & ~(d > hyst * 0.5)
        exp_max = ~(p <= maxlo + offset) & ~(p >= maxup)
        exp_min = ~(p <= minlo) & ~(p >= minup - offset)
    tr = hal.run(N, inputs={j + "current-pos": p, j + "homing": h},
                 record=[j + o for o in outs])
    exp_both = (exp_max | exp_min) & ~h
    assert (tr[j + "homesw-out"] == exp_home).all()
    assert (tr[j + "maxsw-out"] == exp_max).all()
    assert (tr[j + "minsw-out"] == exp_min).all()
    assert (tr[j + "bothsw-out"] == exp_both).all()
    assert (tr[j + "bothsw-homesw-out"] == (exp_both | exp_home)).all()


@SETTINGS
@given(speed=st.lists(edgy, min_size=N, max_size=N),
       ppr=st.integers(1, 50))
def test_sim_encoder_steps_are_quadrature(hal, speed, ppr):
    """At most one count a period, each a single quadrature step in the
    direction of the count; a NaN speed makes no step."""
    if not hal.components("sim_encoder"):
        setup(hal, "sim_encoder", "sim-encoder.make-pulses",
              "sim-encoder.update-speed")
    e = "sim-encoder.0."
    hal.setp(e + "ppr", ppr)
    raw0 = hal.getp(e + "rawcounts")
    tr = hal.run(N, inputs={e + "speed": np.array(speed)},
                 record=[e + "phase-A", e + "phase-B", e + "rawcounts"])
    raw = np.concatenate([[raw0], tr[e + "rawcounts"]]).astype(np.int64)
    # the quadrature states in counting order: (A, B) = 10 11 01 00
    order = {(1, 0): 0, (1, 1): 1, (0, 1): 2, (0, 0): 3}
    state = [order[(int(a), int(b))] for a, b in
             zip(tr[e + "phase-A"], tr[e + "phase-B"])]
    steps = np.diff(raw)
    assert (np.abs(steps) <= 1).all()
    for k in range(1, N):
        assert (state[k] - state[k - 1]) % 4 == steps[k] % 4
    # make-pulses runs first: a period steps on the previous period's speed
    for k in range(1, N):
        if np.isnan(speed[k - 1]):
            assert steps[k] == 0


@SETTINGS
@given(ins=st.lists(signal, min_size=4, max_size=4),
       sel=st.lists(st.integers(0, 2**31 - 8), min_size=N, max_size=N),
       selbits=st.lists(st.integers(0, 3), min_size=N, max_size=N))
def test_mux_generic_copies_the_selected_input(hal, ins, sel, selbits):
    """Without debounce, out is the input sel-int + sel-bits selects, the
    last one for a selection past it; selected shows the number asked
    for."""
    once(hal, "mux_generic", "mux-gen.00", args=("config=ff4",))
    m = "mux-gen.00."
    hal.set({m + "debounce-us": 0, m + "suppress-no-input": False})
    s = np.array(sel, dtype=np.int64) + np.array(selbits)
    inputs = {f"{m}in-float-{k:02d}": np.array(ins[k]) for k in range(4)}
    inputs[m + "sel-int"] = np.array(sel, dtype=np.uint32)
    inputs.update({f"{m}sel-bit-{b:02d}": (np.array(selbits) >> b) & 1 == 1
                   for b in range(2)})
    out = hal.run(N, inputs=inputs, record=[m + "out-float"])[m + "out-float"]
    assert (out == np.array(ins)[np.minimum(s, 3), np.arange(N)]).all()
    assert hal.getp(m + "selected") == s[-1]


@SETTINGS
@given(value=st.lists(edgy, min_size=N, max_size=N), rev=bits)
def test_bldc_out_dir(hal, value, rev):
    """out-dir is the sign of value turned round by rev, FALSE for 0 or
    NaN (as the reference), from the first period on."""
    once(hal, "bldc", "bldc.0", args=("cfg=a6",))
    v = np.array(value)
    r = np.array(rev)
    out = hal.run(N, inputs={"bldc.0.value": v, "bldc.0.rev": r},
                  record=["bldc.0.out-dir"])["bldc.0.out-dir"]
    with np.errstate(invalid="ignore"):
        exp = np.where(v > 0, r, np.where(v < 0, ~r, False))
    assert (out == exp).all()
