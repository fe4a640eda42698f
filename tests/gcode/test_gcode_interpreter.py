"""Tests of the G-code interpreter (halsdk.gcode.interp)."""

from __future__ import annotations

import math

import pytest

from halsdk.gcode import Block, GCodeError, Parameters, Program
from halsdk.gcode import canon as C
from halsdk.gcode.interp import Interpreter
from halsdk.machine.tooltable import ToolTable

TABLE = """T1 P1 Z10 D6 ;six
T2 P2 Z20 X1 D3
T5 P5 Z50 D10
"""


def make(random: bool = False, units: str = "mm", params=None):
    params = params or Parameters()
    tools = ToolTable.parse(TABLE, random=random)
    rec = C.RecordingCanon()
    interp = Interpreter(params, tools, rec, random_toolchanger=random,
                         units=units)
    return interp, rec


def run(text: str, **kw):
    interp, rec = make(**kw)
    interp.run(Program(text, params=interp.params))
    return interp, rec


def moves(rec):
    return rec.of_type(C.StraightTraverse, C.StraightFeed, C.ArcFeed,
                       C.Probe, C.SyncedFeed)


def xyz(cmd):
    return tuple(round(v, 6) for v in cmd.end[:3])


def err(text: str, **kw) -> GCodeError:
    with pytest.raises(GCodeError) as info:
        run(text, **kw)
    return info.value


# -- basics, order, modal groups ---------------------------------------------

def test_g0_g1_positions_and_feed():
    interp, rec = run("G0 X1 Y2\nG1 Z-1 F300\nX5\n")
    m = moves(rec)
    assert [type(c) for c in m] == [C.StraightTraverse, C.StraightFeed,
                                    C.StraightFeed]
    assert xyz(m[0]) == (1, 2, 0) and xyz(m[2]) == (5, 2, -1)
    assert m[1].feed == 300 and m[2].line == 3
    assert interp.program_position()[:3] == [5, 2, -1]


def test_order_of_execution_within_block():
    # written backwards: motion must still come after F, S, T, M3, M8
    _, rec = run("G1 X1 M8 M3 T1 S1000 F200\n")
    kinds = [type(c) for c in rec.commands]
    assert kinds == [C.SetFeedRate, C.SpindleSpeed, C.SelectTool,
                     C.SpindleOn, C.Coolant, C.StraightFeed]
    assert rec.commands[3].rpm == 1000


def test_stop_comes_after_motion_and_message_first():
    _, rec = run("G0 X1 M0 (MSG, hello)\n")
    assert [type(c) for c in rec.commands] == [C.Message, C.StraightTraverse,
                                               C.ProgramPause]


def test_two_codes_of_one_group_names_column():
    e = err("G0 X1 G1 Y2\n")
    assert e.message == "Two g codes used from same modal group"
    assert e.column == 7 and e.line == 1
    e = err("G1 F1\nM3 M4\n")
    assert e.line == 2 and e.column == 4
    assert e.message == "Two m codes used from same modal group"


def test_unknown_code_and_axis_words_without_motion():
    assert err("G12 X1\n").message == "Unknown g code used"
    assert err("M55\n").message == "Unknown m code used: M55"
    e = err("G80\nX1\n")
    assert e.line == 2 and e.message == ("Cannot use axis values without a "
                                         "g code that uses them")
    assert err("G80 X1\n").message == "Cannot use axis values with g80"


def test_words_without_a_user_are_errors():
    e = err("G0 X1 R5\n")
    assert e.column == 7 and e.message == ("R word with no g code that "
                                           "uses it")
    assert "H word" in str(err("G49 H1\n"))
    assert "Q word" in str(err("F1 G81 R1 Z-1\nG80 Q1\n"))
    assert "P word" in str(err("G0 X1\nG1 X2 P1 F1\n"))


def test_group0_and_motion_both_using_axes():
    e = err("G92 G1 X1 F10\n")
    assert e.message == "Cannot use two g codes that both use axis values"


def test_feed_errors():
    assert "zero feed" in str(err("G1 X1\n"))
    e = err("G93 G1 X1 F2\nG1 X2\n")
    assert e.line == 2 and "inverse time" in str(e)


def test_inverse_time_feed_is_length_times_f():
    _, rec = run("G93 G1 X30 Y40 F2\n")
    assert rec.of_type(C.SetFeedMode)[0].mode == "inverse_time"
    assert moves(rec)[0].feed == pytest.approx(100.0)


# -- units ---------------------------------------------------------------------

def test_g20_on_metric_machine_converts():
    interp, rec = run("G20 G1 X1 F10\nG91 X0.5\n")
    m = moves(rec)
    assert m[0].end[0] == pytest.approx(25.4) and m[1].end[0] == \
        pytest.approx(38.1)
    # F came before G20 in the order of execution: 10 mm/min
    assert m[0].feed == pytest.approx(10)
    interp.execute(next(iter(Program("F10\n").blocks())))
    assert interp.feed == pytest.approx(254)
    assert interp.params.get("_x") == pytest.approx(1.5)
    assert interp.params.get("_imperial") == 1


def test_inch_machine_g21():
    _, rec = run("G21 G0 X25.4 A10\n", units="inch")
    assert moves(rec)[0].end[0] == pytest.approx(1.0)
    assert moves(rec)[0].end[3] == pytest.approx(10.0)  # rotary unscaled


# -- arcs ---------------------------------------------------------------------

def test_arc_ijk_quarter_circle():
    _, rec = run("G0 X10\nF100\nG3 X0 Y10 I-10 J0\n")
    arc = rec.of_type(C.ArcFeed)[0]
    assert arc.center == pytest.approx((0, 0)) and arc.turn == 1
    assert arc.plane == 17 and xyz(arc)[:2] == (0, 10)


def test_arc_r_form_both_signs_and_direction():
    _, rec = run("G0 X0 Y0\nF100\nG2 X10 Y0 R5\nG2 X20 Y0 R-7.0710678\n")
    a, b = rec.of_type(C.ArcFeed)
    assert a.center == pytest.approx((5, 0)) and a.turn == -1
    # negative R: more than a half circle, centre on the other side
    assert b.center == pytest.approx((15, 5))
    _, rec2 = run("G0 X10\nF100\nG2 X20 Y0 R7.0710678\n")
    assert rec2.of_type(C.ArcFeed)[0].center[1] == pytest.approx(
        -b.center[1])


def test_full_circle_turns_and_helix():
    _, rec = run("G0 X10\nF100\nG2 I-10 Z-3 P3\n")
    arc = rec.of_type(C.ArcFeed)[0]
    assert arc.turn == -3 and arc.end[2] == -3 and arc.center == \
        pytest.approx((0, 0))
    # inverse-time feed uses the helix length: 3 turns of r=10, 3 down
    _, rec = run("G0 X10\nG93 G3 I-10 P1 Z-3 F1\n")
    assert rec.of_type(C.ArcFeed)[0].feed == pytest.approx(
        math.hypot(2 * math.pi * 10, 3))


def test_arc_planes():
    _, rec = run("F1\nG18 G0 X10\nG2 X0 Z10 I-10\nG19 G0 Y0 Z0\n"
                 "G0 Y10\nG3 Y0 Z10 J-10\n")
    a, b = rec.of_type(C.ArcFeed)
    assert a.plane == 18 and a.center == pytest.approx((0, 0))  # (z, x)
    assert b.plane == 19 and b.center == pytest.approx((0, 0))  # (y, z)


def test_arc_errors():
    # the reference's words, the points in program coordinates
    assert err("G0 X10\nF1\nG3 X0 Y11 I-10\n").message == (
        "Radius to end of arc differs from radius to start: "
        "start=(X10.0000,Y0.0000) center=(X0.0000,Y0.0000) "
        "end=(X0.0000,Y11.0000) r1=10.0000 r2=11.0000 abs_err=1 "
        "rel_err=9.0909%")
    assert err("G10 L2 P1 X5\nF1 G2 X1 I0 J0\n").message == (
        "Zero-radius arc: start=(X-5.0000,Y0.0000) "
        "center=(X-5.0000,Y0.0000) end=(X1.0000,Y0.0000) r1=0.0000 "
        "r2=6.0000")
    assert err("F1 G2 X10 R2\n").message == ("Arc radius too small to reach "
                                            "end point")
    assert err("F1 G2 X0 Y0 R2\n").message == ("Current point same as end "
                                              "point of arc")
    assert err("F1 G2 Z1 R1\n").message == ("X and y words missing for arc "
                                           "in xy plane")
    assert err("F1 G2 X1\n").message == "R i j k words all missing for arc"
    assert err("F1 G90.1 G2 X1 I1\n").message == (
        "J word missing in absolute center arc")
    assert err("G0 X1\nF1 G2 X1 I-1 P0.5\n").message == (
        "P value not an integer with M19 G2 or G3")
    assert err("G0 X1\nF1 G2 X1 I-1 P0\n").message == (
        "P value should be 1 or greater with G2 or G3")
    # the feed is checked before the geometry
    assert err("G2 X3 I5\n").message == "Cannot make arc with zero feed rate"
    assert err("G93 G2 X3 I5\n").message == (
        "F word missing with inverse time arc move")
    # as in the reference, an arc or a cycle needs an axis word
    assert err("G0 X1\nF1 G38.2\n").message == (
        "All axes missing with motion code")


def test_absolute_arc_centre_g90_1():
    _, rec = run("G10 L2 P1 X100\nG0 X10\nF1\nG90.1 G3 X-10 I0 J0\n")
    assert rec.of_type(C.ArcFeed)[0].center == pytest.approx((100, 0))


# -- dwell, planes, path control --------------------------------------------

def test_dwell_and_term_cond():
    _, rec = run("G4 P1.5\nG61\nG61.1\nG64 P0.1 Q0.05\nG20 G64 P0.01\n")
    assert rec.of_type(C.Dwell)[0].seconds == 1.5
    modes = rec.of_type(C.SetTermCond)
    assert [c.mode for c in modes] == ["exact_path", "exact_stop", "blend",
                                       "blend"]
    assert modes[2].p == 0.1 and modes[2].q == 0.05
    assert modes[3].p == pytest.approx(0.254)
    assert err("G4\n").message == "Dwell time missing with g4"


# -- offsets ------------------------------------------------------------------

def test_g10_l2_and_coordinate_systems():
    interp, rec = run("G10 L2 P2 X10 Y20\nG55\nG0 X1 Y1\nG54 G0 X1\n")
    m = moves(rec)
    assert xyz(m[0]) == (11, 21, 0) and xyz(m[1])[0] == 1
    assert interp.params.get(5241) == 10 and interp.params.get(5220) == 1
    assert rec.of_type(C.SetG5xOffset)[0].index == 2


def test_g10_l20_and_g92_family():
    interp, rec = run("G0 X5 Y5\nG10 L20 P1 X0\nG0 X1\n")
    assert moves(rec)[-1].end[0] == 6 and interp.params.get(5221) == 5
    interp, rec = run("G0 X5\nG92 X0\nG0 X1\n")
    assert moves(rec)[-1].end[0] == 6 and interp.params.get(5211) == 5
    assert interp.params.get(5210) == 1
    p = interp.params
    interp.execute(next(iter(Program("G92.2\n").blocks())))
    assert interp.g92[0] == 0 and p.get(5211) == 5
    interp.execute(next(iter(Program("G92.3\n").blocks())))
    assert interp.g92[0] == 5
    interp.execute(next(iter(Program("G92.1\n").blocks())))
    assert interp.g92[0] == 0 and p.get(5211) == 0 and p.get(5210) == 0


def test_g10_l2_rotation_turns_about_the_g5x_origin():
    # G10 L2 R: program X1 Y0 in a system at (5, 5) turned 90 degrees
    interp, rec = run("G10 L2 P1 X5 Y5 R90\nG0 X1 Y0\n")
    end = moves(rec)[-1].end
    assert end[0] == pytest.approx(5) and end[1] == pytest.approx(6)
    assert interp.params.get(5230) == 90
    assert interp.program_position()[0] == pytest.approx(1)
    # an incremental centre turns with the system: a half circle from
    # program (0, 0) to (2, 0) about (1, 0) has its machine centre at (5, 6)
    interp, rec = run("G10 L2 P1 X5 Y5 R90\nG0 X0 Y0\n"
                      "G2 X2 Y0 I1 J0 F100\n")
    arc = rec.of_type(C.ArcFeed)[-1]
    assert arc.center == pytest.approx((5, 6))
    assert arc.end[:2] == pytest.approx((5, 7))
    # G92 in a rotated system: the current point reads the given value
    interp, _ = run("G10 L2 P1 R30\nG0 X3 Y4\nG92 X0 Y0\n")
    assert interp.program_position()[:2] == pytest.approx([0, 0])
    assert "not supported" in str(err("G10 L2 P1 R30\nG18\n"
                                      "G2 X1 Z1 R1 F10\n"))


def test_g92_persisted_in_parameters_restored_at_start():
    p = Parameters()
    p.set(5210, 1)
    p.set(5213, -4)
    interp, _ = make(params=p)
    assert interp.g92[2] == -4 and interp.program_position()[2] == 4


def test_g53_machine_coordinates():
    _, rec = run("G10 L2 P1 X100\nG53 G0 X1\nG0 X1\n")
    assert [c.end[0] for c in moves(rec)] == [1, 101]
    assert err("G53 G2 X1 R3 F1\n").message == "Must use g0 or g1 with g53"


def test_g28_g30_and_dot_one():
    interp, rec = run("G0 X3 Y4 Z5\nG28.1\nG0 X0 Y0 Z0\nG28 Z1\nG28\n")
    assert interp.params.get(5161) == 3
    m = moves(rec)
    assert xyz(m[2]) == (0, 0, 1) and xyz(m[3]) == (0, 0, 5)
    assert xyz(m[4]) == (3, 4, 5)
    p = Parameters()
    p.set(5181, 7)
    interp, _ = make(params=p)
    interp.run(Program("G30\n", params=p))
    assert interp.pos[0] == 7


# -- tools ----------------------------------------------------------------------

def test_t_m6_g43_nonrandom_and_params():
    interp, rec = run("T2 M6\nG43\nG0 Z0\nG49\nG0 Z0\n")
    assert rec.of_type(C.SelectTool)[0] == C.SelectTool(2, 2, 1)
    assert rec.of_type(C.ChangeTool)[0].tool == 2
    p = interp.params
    assert p.get(5400) == 2 and p.get(5403) == 20 and p.get(5401) == 1
    assert p.get(5410) == 3
    m = moves(rec)
    assert m[0].end[2] == 20 and m[1].end[2] == 0
    assert interp.tools.spindle.tool == 2
    assert interp.tools.entry(2).tool == 2    # nonrandom: copied, not moved


def test_g43_h_and_g43_1():
    interp, rec = run("G43 H5\nG0 Z1\nG43.1 Z2.5\nG0 Z1\n")
    assert [c.end[2] for c in moves(rec)] == [51, 3.5]
    assert interp.params.get("_tool_offset") == 1
    assert err("G43 H9\n").message == ("Requested tool 9 not found in the "
                                       "tool table")


def test_t_unknown_tool_and_m6_without_t():
    e = err("G0 X1\nT9\n")
    assert e.line == 2 and e.column == 1 and "tool 9" in str(e)
    assert "M6 without" in str(err("M6\n"))


def test_t0_nonrandom_empties_spindle():
    interp, _ = run("T1 M6\nT0 M6\n")
    assert interp.tools.spindle.tool == 0 and interp.params.get(5400) == 0
    assert interp.params.get(5403) == 0


def test_random_changer_swaps_pockets():
    interp, rec = run("T1 M6\nT2 M6\n", random=True)
    t = interp.tools
    assert t.spindle.tool == 2 and t.entry(2).tool == 1
    assert t.pocket_of(1) == 2 and interp.params.get(5403) == 20
    # T of the tool in the spindle: pocket 0
    interp.execute(next(iter(Program("T2\n").blocks())))
    assert rec.of_type(C.SelectTool)[-1].pocket == 0


def test_m61_sets_tool_without_change():
    interp, rec = run("M61 Q5\nG43\nG0 Z0\n")
    assert rec.of_type(C.ChangeToolNumber)[0].tool == 5
    assert not rec.of_type(C.ChangeTool)
    assert moves(rec)[0].end[2] == 50 and interp.params.get(5400) == 5
    assert err("M61\n").message == ("Need non-negative Q-word to specify "
                                   "tool number with M61")


def test_g10_l1_updates_params_only_for_current_tool():
    interp, rec = run("T1 M6\nG10 L1 P2 Z7 R2\n")
    assert interp.tools.entry(2).offset[2] == 7
    assert interp.tools.entry(2).diameter == 4
    assert interp.params.get(5403) == 10   # the current tool is T1
    cmds = rec.of_type(C.SetToolTableEntry)
    assert len(cmds) == 1 and cmds[0].pocket == 2
    interp.execute(next(iter(Program("G10 L1 P1 Z3\n").blocks())))
    assert interp.params.get(5403) == 3
    cmds = rec.of_type(C.SetToolTableEntry)
    # nonrandom, loaded tool: home pocket then pocket 0
    assert [c.pocket for c in cmds[1:]] == [1, 0]
    assert interp.tools.spindle.offset[2] == 3


def test_g10_l1_random_loaded_tool_uses_pocket_0():
    interp, rec = run("T1 M6\nG10 L1 P1 Z4\n", random=True)
    cmds = rec.of_type(C.SetToolTableEntry)
    assert [c.pocket for c in cmds] == [0]
    assert interp.tools.spindle.offset[2] == 4


def test_g10_l10_and_l11():
    interp, _ = run("G10 L2 P1 Z100\nG10 L2 P9 Z40\nG0 Z0\n"
                    "G10 L10 P1 Z5\n")
    # machine Z is 100; with TLO t, program Z = 100 - 100 - t = 5
    assert interp.tools.entry(1).offset[2] == -5
    interp.execute(next(iter(Program("G10 L11 P2 Z5\n").blocks())))
    assert interp.tools.entry(2).offset[2] == 55


# -- probing --------------------------------------------------------------------

def test_probe_and_result_parameters():
    interp, rec = run("G10 L2 P1 Z1\nF50\nG38.2 Z-10\n")
    pr = rec.of_type(C.Probe)[0]
    assert pr.kind == "38.2" and pr.end[2] == -9 and pr.feed == 50
    interp.probe_result((0, 0, -3, 0, 0, 0, 0, 0, 0), True)
    assert interp.params.get(5063) == -4 and interp.params.get(5070) == 1
    assert interp.program_position()[2] == -4
    e = err("F10\nG38.3 Z0\n")
    assert e.message == "Start point too close to probe point"
    assert e.column == 1
    # (the reference probes at the G94 feed rate, zero here)
    assert err("G93 G38.4 Z1 F1\n").message == ("Cannot probe with zero "
                                                "feed rate")


# -- canned cycles -------------------------------------------------------------

def drill(text: str, **kw):
    _, rec = run(text, **kw)
    return [(type(c).__name__[8] if isinstance(c, (C.StraightTraverse,
                                                  C.StraightFeed))
             else type(c).__name__, xyz(c) if hasattr(c, "end") else None)
            for c in rec.commands if not isinstance(c, C.SetFeedRate)]


def test_g81_g98_g99_and_modal_repeat():
    out = drill("G0 Z10\nF100\nG98 G81 X1 Y2 R2 Z-3\nX5\nG80\n")
    assert out[1:] == [
        ("T", (1, 2, 10)), ("T", (1, 2, 2)), ("F", (1, 2, -3)),
        ("T", (1, 2, 10)),
        ("T", (5, 2, 10)), ("T", (5, 2, 2)), ("F", (5, 2, -3)),
        ("T", (5, 2, 10))]
    out = drill("G0 Z10\nF100\nG99 G81 X1 R2 Z-3\n")
    assert out[-1] == ("T", (1, 0, 2))


def test_g91_canned_with_l_repeats():
    out = drill("G0 Z5\nF10\nG91 G81 X2 R-3 Z-4 L3\n")
    holes = [p for k, p in out if k == "F"]
    assert holes == [(2, 0, -2), (4, 0, -2), (6, 0, -2)]


def test_g82_g85_g89_g86():
    out = drill("F10\nG0 Z5\nG82 R1 Z-1 P0.5\n")
    assert ("Dwell", None) in out
    out = drill("F10\nG0 Z5\nG85 R1 Z-1\n")
    assert [k for k, _ in out[-3:]] == ["F", "F", "T"]
    out = drill("F10\nG0 Z5\nG89 R1 Z-1 P2\n")
    assert [k for k, _ in out[-4:]] == ["F", "Dwell", "F", "T"]
    out = drill("S100 M3 F10\nG0 Z5\nG86 R1 Z-1\n")
    assert [k for k, _ in out[-4:]] == ["SpindleOff", "T", "SpindleOn", "T"]


def test_g83_and_g73_pecks():
    out = drill("F10\nG0 Z5\nG83 R1 Z-2 Q1.5\n")
    feeds = [p[2] for k, p in out if k == "F"]
    assert feeds == [-0.5, -2]
    assert (("T", (0, 0, 1)) in out[4:]) and ("T", (0, 0, -0.246)) in out
    out = drill("F10\nG0 Z5\nG73 R1 Z-2 Q1\n")
    assert [p[2] for k, p in out if k == "F"] == [0, -1, -2]
    assert ("T", (0, 0, 0.254)) in out
    assert err("F1 G83 R1 Z-1\n").message == "Q word missing with g83"


def test_canned_errors():
    assert err("F1 G81 Z-1\n").message == ("R clearance plane unspecified "
                                          "in cycle")
    assert err("F1 G81 R-2 Z-1\n").message == ("R less than z in cycle in "
                                              "xy plane")
    assert "not supported" in str(err("F1 G87 R1 Z-1\n"))


def test_g84_tap_sequence():
    out = drill("S200 M3 F250\nG0 Z5\nG84 X1 R1 Z-2 P0.5\n")
    assert out[3:] == [
        ("T", (1, 0, 5)), ("T", (1, 0, 1)), ("F", (1, 0, -2)),
        ("SpindleOff", None), ("SpindleOn", None), ("Dwell", None),
        ("F", (1, 0, 1)), ("SpindleOff", None), ("SpindleOn", None),
        ("T", (1, 0, 5))]
    _, rec = run("S200 M3 F250\nG0 Z5\nG84 X1 R1 Z-2 P0.5\n")
    ons = rec.of_type(C.SpindleOn)
    assert [c.direction for c in ons] == [1, -1, 1]
    assert all(c.rpm == 200 for c in ons)
    assert rec.of_type(C.Dwell)[0].seconds == 0.5
    assert all(c.feed == 250 for c in rec.of_type(C.StraightFeed))
    out = drill("S200 M3 F250\nG0 Z5\nG84 R1 Z-2\n")
    assert "Dwell" not in [k for k, _ in out]


def test_g88_sequence():
    out = drill("S100 M4 F10\nG0 Z5\nG88 X2 R1 Z-1 P1\n")
    assert out[3:] == [
        ("T", (2, 0, 5)), ("T", (2, 0, 1)), ("F", (2, 0, -1)),
        ("Dwell", None), ("SpindleOff", None), ("ProgramPause", None),
        ("SpindleOn", None), ("T", (2, 0, 5))]
    _, rec = run("S100 M4 F10\nG0 Z5\nG88 X2 R1 Z-1 P1\n")
    assert rec.of_type(C.SpindleOn)[-1].direction == -1


def test_g84_g88_retract_modes_and_repeats():
    out = drill("S100 M3 F10\nG0 Z10\nG99 G84 X1 R2 Z-3\n")
    assert out[-1] == ("T", (1, 0, 2))
    out = drill("S100 M3 F10\nG0 Z10\nG98 G88 X1 R2 Z-3\n")
    assert out[-1] == ("T", (1, 0, 10))
    out = drill("S100 M3 F10\nG0 Z5\nG91 G84 X2 R-3 Z-4 L2\n")
    assert [p for k, p in out if k == "F"] == [
        (2, 0, -2), (2, 0, 2), (4, 0, -2), (4, 0, 2)]
    out = drill("S100 M3 F10\nG0 Z5\nG91 G88 Y1 R-3 Z-4 L2\n")
    assert [p for k, p in out if k == "F"] == [(0, 1, -2), (0, 2, -2)]
    assert [k for k, _ in out].count("ProgramPause") == 2


def test_g84_g88_errors():
    e = err("S100 M3 F10\nG84 Z-1\n")
    assert (e.line, e.column) == (2, 1) and "R clearance plane" in str(e)
    e = err("S100 M3 F10\nG88 X1 R1\n")
    assert (e.line, e.column) == (2, 1) and e.message == (
        "Z value unspecified in xy plane canned cycle")
    e = err("S100 M3 F10\nG88 R1\n")
    assert (e.line, e.column) == (2, 1)
    assert e.message == "All axes missing with motion code"
    e = err("S100 M4 F10\n G84 R1 Z-1\n")
    assert (e.line, e.column) == (2, 2)
    assert e.message == "Spindle turning counterclockwise in G84"
    e = err("F10\nG88 R1 Z-1\n")
    assert e.line == 2 and e.message == "Spindle not turning in g88"
    e = err("S100 M3\nG84 R1 Z-1\n")
    assert e.line == 2 and "feed rate" in str(e)


# -- spindle, coolant, I/O, program end -------------------------------------

def test_spindle_coolant_and_io():
    interp, rec = run("S500 M4\nM5\nM7\nM8\nM9\nM62 P1\nM63 P1\nM64 P2\n"
                      "M65 P2\nM66 P3 L1 Q2\nM66 E1 L0\nM67 E1 Q2.5\n"
                      "M68 E0 Q1\n")
    assert rec.of_type(C.SpindleOn)[0].direction == -1
    assert [c.kind for c in rec.of_type(C.Coolant)] == ["mist", "flood",
                                                         "off"]
    assert rec.of_type(C.SyncDout) == [C.SyncDout(1, True, 6),
                                       C.SyncDout(1, False, 7)]
    assert rec.of_type(C.DoutNow)[1] == C.DoutNow(2, False, 9)
    w = rec.of_type(C.WaitInput)
    assert w[0] == C.WaitInput(3, True, 1, 2.0, 10) and not w[1].digital
    assert rec.of_type(C.SyncAout)[0].value == 2.5
    assert rec.of_type(C.AoutNow)[0].index == 0
    with pytest.raises(GCodeError, match="Invalid to select both a digital "
                       "and an analog input with M66"):
        interp.execute(Block("t.ngc", 1, "", m=[66], words={"p": 1, "e": 1}))
    with pytest.raises(GCodeError, match="t.ngc:2:5: M67 needs a Q"):
        interp.execute(Block("t.ngc", 2, "", m=[67], words={"e": 1},
                             columns={"m67": 5}))


def test_m66_result_parameter():
    interp, _ = make()
    interp.input_result(1)
    assert interp.params.get(5399) == 1


def test_m2_resets_modes_and_stops():
    interp, rec = run("G55 G91 G18 S1 M3 M8\nM2\nG0 X100\n")
    assert interp.ended and rec.of_type(C.ProgramEnd)[0].rewind is False
    m = interp.modal
    assert (m.coord_system, m.distance, m.plane, m.spindle) == \
        (540, 900, 170, 50)
    assert not moves(rec)         # nothing after M2
    _, rec = run("M1\nM30\n")
    assert rec.of_type(C.OptionalPause) and \
        rec.of_type(C.ProgramEnd)[0].rewind


def test_g33():
    _, rec = run("S100 M3\nG33 Z-10 K1.5\n")
    assert rec.of_type(C.SyncedFeed)[0].pitch == 1.5
    assert err("G33 Z-1\n").message == "K word missing with g33/g33.1"


def xy(cmd):
    return tuple(round(v, 6) + 0.0 for v in cmd.end[:2])


def test_cutter_comp_outside_corners_g41():
    _, rec = run("G0 X0 Y-10\nG41 D1\nG1 X0 Y0 F100\nX10\nM8\nY-10\n"
                 "G40\nG0 X20\n")
    out = rec.commands[rec.commands.index(C.SetFeedRate(100, 3)) + 1:]
    assert [type(c).__name__ for c in out] == [
        "StraightFeed", "ArcFeed", "StraightFeed", "Coolant", "ArcFeed",
        "StraightFeed", "StraightTraverse"]
    assert xy(out[0]) == (-3, 0)
    assert xy(out[1]) == (0, 3) and out[1].center == (0, 0) and \
        out[1].turn == -1
    assert xy(out[2]) == (10, 3) and xy(out[4]) == (13, 0)
    assert xy(out[5]) == (13, -10) and xy(out[6]) == (20, -10)


def test_cutter_comp_inside_corners_g42_and_gouge():
    interp, rec = run("G0 X0 Y-10\nG42 D1\nG1 Y0 F100\nX10\nY-10\nG40\n")
    feeds = [xy(c) for c in rec.of_type(C.StraightFeed)]
    assert feeds == [(3, -3), (7, -3), (7, -10)]
    assert interp.modal.cutter_comp == 400
    e = err("G0 X0 Y-10\nG42 D1\nG1 Y0 F100\nX1\nY-10\n")
    assert e.line == 4 and e.message == (
        "Straight feed in concave corner cannot be reached by the tool "
        "without gouging")


def test_cutter_comp_z_moves_and_refusals():
    _, rec = run("G0 X0 Y-10 Z5\nG41 D1\nG1 Y0 F100\nZ-1\nX10\nG40\n")
    feeds = [tuple(round(v, 6) for v in c.end[:3])
             for c in rec.of_type(C.StraightFeed)]
    assert feeds[:2] == [(-3, 0, 5), (-3, 0, -1)]
    assert xy(rec.of_type(C.ArcFeed)[0]) == (0, 3)
    assert err("G0 X-9\nG41 D1 G1 X0 F1\nG3 X4 R2\n").message == (
        "Tool radius not less than arc radius with comp")
    assert err("G19 G41 D1\n").message == ("Cutter radius compensation "
                                          "allowed only in XY, XZ planes")
    assert err("G18 G41 D1\nG17\n").message == (
        "Cannot change planes with cutter radius compensation on")
    assert err("G41 D1\nG42 D1\n").message == ("Cannot turn cutter radius "
                                               "comp on when on")
    assert "tool 9" in str(err("G41 D9\n"))


def test_predefined_named_parameters():
    interp, _ = run("G91 G0 X2\nF120\nT1 M6\n")
    p = interp.params
    assert p.get("_x") == 2 and p.get("_incremental") == 1
    assert p.get("_feed") == 120 and p.get("_current_tool") == 1
    assert p.get("_coord_system") == 540 and p.get("_metric") == 1


def test_parameters_visible_to_program_expressions():
    _, rec = run("G0 X3\n#1=[#<_x>*2]\nG0 Y#1\n")
    assert xyz(moves(rec)[1]) == (3, 6, 0)


def test_end_state_of_a_job():
    interp, rec = run("""(MSG, job)
G21 G17 G90 G94 G64 P0.05
G10 L2 P9 X50 Y50
G59.3
T1 M6
G43
S2000 M3 M8
G0 X0 Y0 Z5
G1 Z-1 F200
G2 X10 Y0 R5
G0 Z5
M5 M9
""")
    assert interp.pos == [60, 50, 15, 0, 0, 0, 0, 0, 0]
    assert interp.program_position()[:3] == [10, 0, 5]
    assert interp.tlo[2] == 10 and interp.params.get(5220) == 9
    assert interp.modal.gcodes() == (0.0, 17.0, 90.0, 91.1, 94.0, 21.0,
                                     40.0, 43.0, 98.0, 59.3, 64.0)
    assert rec.commands[0] == C.Message("job", 1)
    assert rec.of_type(C.ArcFeed)[0].center == pytest.approx((55, 50))
    assert len(moves(rec)) == 4


def test_random_m61_and_g43_after_swap():
    interp, rec = run("T5 M6\nG43\nM61 Q2\nG43\nG0 Z0\n", random=True)
    assert rec.of_type(C.UseToolLengthOffset)[0].offset[2] == 50
    assert interp.tools.spindle.tool == 2 and interp.current_tool == 2
    assert moves(rec)[0].end[2] == 20


def test_probe_kinds_and_no_tool_table():
    for kind in ("38.2", "38.3", "38.4", "38.5"):
        _, rec = run(f"F5\nG{kind} X1\n")
        assert rec.of_type(C.Probe)[0].kind == kind
    rec = C.RecordingCanon()
    interp = Interpreter(Parameters(), None, rec)
    with pytest.raises(GCodeError, match="Requested tool 1 not found in "
                                         "the tool table"):
        interp.execute(Block("a.ngc", 3, "T1", words={"t": 1},
                             columns={"t": 1}))


def test_m70_m72_and_m73_restore_the_modal_state():
    interp, rec = run("G21 F100 M70\nG18 G20 G91 F2\nM72\nG1 X1\n")
    assert interp.modal.plane == 170 and interp.modal.units == 210
    assert interp.modal.distance == 900
    assert rec.of_type(C.SetPlane)[-1].plane == 17
    assert rec.of_type(C.SetFeedRate)[-1].feed == pytest.approx(100)
    assert moves(rec)[-1].end[0] == pytest.approx(1)
    # M73: the state of the caller comes back when the subroutine returns
    interp, rec = run("o1 sub\nM73\nG20 G91\no1 endsub\no1 call\nG0 X1\n")
    assert interp.modal.units == 210 and interp.modal.distance == 900
    assert moves(rec)[-1].end[0] == pytest.approx(1)
    assert err("M70\nM71\nM72\n").message == (
        "Cannot restore context from invalid stack frame - missing M70/M73?")


def test_g76_threading_passes():
    # external thread from X1 Z1 to Z-1: depths 0.02, 0.04, then K 0.05
    _, rec = run("G18 G0 X1 Z1\nG76 P0.1 Z-1 I-0.1 J0.02 K0.05\n")
    synced = rec.of_type(C.SyncedFeed)
    assert [round(c.end[0], 6) for c in synced] == [0.88, 0.86, 0.85]
    assert all(c.pitch == pytest.approx(0.1) for c in synced)
    assert all(round(c.end[2], 6) == -1 for c in synced)
    # it ends at the start X and the end Z
    assert xyz(moves(rec)[-1]) == (1, 0, -1)
    # a spring pass repeats the last depth
    _, rec = run("G18 G0 X1 Z1\nG76 P0.1 Z-1 I-0.1 J0.02 K0.05 H1\n")
    assert len(rec.of_type(C.SyncedFeed)) == 4
    assert err("G76 P0.1 Z-1 I-0.1 J0.02\n").message == (
        "I J or K words missing with G76")


def test_cutter_comp_on_arcs_meets_the_offset_lines():
    # tool radius 3 left of a clockwise arc: its offset path has radius 13
    _, rec = run("G0 X-10 Y0\nG41 D1 G1 X0 Y0 F100\nG2 X20 Y0 I10 J0\n"
                 "G1 X30\nG40\n")
    feeds = rec.of_type(C.StraightFeed)
    h = math.sqrt(13 ** 2 - 3 ** 2)
    assert xyz(feeds[0]) == pytest.approx((10 - h, 3, 0))
    arc = rec.of_type(C.ArcFeed)[0]
    assert arc.center == pytest.approx((10, 0)) and arc.turn == -1
    assert xyz(arc) == pytest.approx((10 + h, 3, 0))
    assert xyz(feeds[1]) == pytest.approx((30, 3, 0))


def test_g5_splines_become_short_feeds_on_the_curve():
    _, rec = run("G5 I0 J10 P0 Q10 X10 Y0 F100\n")
    feeds = rec.of_type(C.StraightFeed)
    assert len(feeds) > 10
    assert xyz(feeds[-1]) == (10, 0, 0)
    # the curve 0,0 -> 10,0 with controls (0,10), (10,10) peaks at 7.5
    assert max(c.end[1] for c in feeds) == pytest.approx(7.5, abs=1e-3)
    # G5.1: a parabola through its control's midpoints; both I and J
    _, rec = run("G5.1 I5 J10 X10 Y0 F100\n")
    assert max(c.end[1] for c in rec.of_type(C.StraightFeed)) == \
        pytest.approx(5, abs=1e-3)
    assert "both I and J" in str(err("G5.1 I5 X10 F100\n"))
    assert "XY plane" in str(err("G18 G5 I1 J1 P1 Q1 X1 F100\n"))


def test_ini_named_parameters_read_the_ini_upper_case():
    values = {("AXIS_X", "MAX_LIMIT"): "10.5", ("SETUP", "NAME"): "text"}
    interp, rec = make()
    interp.ini = lambda section, key: values.get((section, key))
    interp.run(Program("G0 X#<_ini[axis_x]max_limit>\n"
                       "#1 = [EXISTS[#<_ini[AXIS_X]NOPE>]]\n",
                       params=interp.params))
    assert xyz(moves(rec)[-1]) == (10.5, 0, 0)
    assert interp.params.get(1) == 0
    with pytest.raises(GCodeError, match="not defined"):
        interp.run(Program("#2 = #<_ini[setup]name>\n",
                           params=interp.params))
    with pytest.raises(GCodeError, match="read-only"):
        interp.run(Program("#<_ini[axis_x]max_limit> = 1\n",
                           params=interp.params))


def test_tool_and_position_parameters_are_read_only():
    for number in (5400, 5413, 5420, 5428):
        assert err(f"#{number} = 1\n").message == "Parameter is readonly"
    interp, _ = run("#5399 = 2\n#5429 = 3\nT1 M6\n")
    assert interp.params.get(5429) == 3 and interp.params.get(5400) == 1


def test_spindle_modes_on_a_machine_and_the_predefined_names():
    """A machine's interpreter runs G97 (its only spindle mode) and
    refuses G96; the predefined names read the modal state."""
    interp, rec = run("G21 G97 S500 M3\n#1 = #<_spindle_rpm_mode>\n"
                      "#2 = #<_spindle_css_mode>\n#3 = #<_task>\n"
                      "G0 X3 Y4\n#4 = #<_abs_x>\nG20\n#5 = #<_abs_y>\n"
                      "T2 M6\n#6 = #<_current_pocket>\nM2\n")
    values = [interp.params.get(i) for i in range(1, 7)]
    assert values == [1.0, 0.0, 0.0, 3.0, pytest.approx(4 / 25.4), 2.0]
    e = err("G21 G96 S100 D2000 M3\nM2\n")
    assert e.line == 1 and "G96" in str(e)
