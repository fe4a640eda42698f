"""The status snapshot of a machine: what the task publishes on the
status channel every cycle, field by field as
:mod:`halsdk.channels.statusfields` names them (the reference's
``linuxcnc.stat`` attributes)."""

from __future__ import annotations

import os
from typing import Any

from halsdk.machine.task import TaskState
from halsdk.motion.protocol import JointFlag, Mode

__all__ = ["build_snapshot"]

# the limit mask bits of the reference's ``limit`` per joint
_MIN_HARD, _MAX_HARD, _MIN_SOFT, _MAX_SOFT = 1, 2, 4, 8
# TRAJ_MODE_* of motion's modes (free, coord, teleop)
_TRAJ_MODE = {int(Mode.FREE): 1, int(Mode.COORD): 2, int(Mode.TELEOP): 3}
_F = JointFlag
_ENABLED, _INPOS, _HOMING, _HOMED = (int(_F.ENABLED), int(_F.INPOS),
                                     int(_F.HOMING), int(_F.HOMED))
_FAULT, _NEG_SOFT, _POS_SOFT = int(_F.FAULT), int(_F.NEG_SOFT), \
    int(_F.POS_SOFT)
_NEG_HARD, _POS_HARD = int(_F.NEG_HARD), int(_F.POS_HARD)


def _limit_mask(f: int) -> int:
    return ((_MIN_HARD if f & _NEG_HARD else 0)
            | (_MAX_HARD if f & _POS_HARD else 0)
            | (_MIN_SOFT if f & _NEG_SOFT else 0)
            | (_MAX_SOFT if f & _POS_SOFT else 0))


def _joint_dict(j: dict, override: bool) -> dict:
    f = j["flags"]
    return {
        "jointType": 1, "units": 1.0, "backlash": j["backlash"],
        "min_position_limit": j["min_pos_limit"],
        "max_position_limit": j["max_pos_limit"],
        "max_ferror": j["max_ferror"], "min_ferror": j["min_ferror"],
        "ferror_current": j["ferror"],
        "ferror_highmark": j["ferror_high_mark"],
        "output": j["pos_cmd"], "input": j["pos_fb"],
        "velocity": j["vel_cmd"],
        "inpos": int(bool(f & _INPOS)), "homing": int(bool(f & _HOMING)),
        "homed": int(bool(f & _HOMED)), "fault": int(bool(f & _FAULT)),
        "enabled": int(bool(f & _ENABLED)),
        "min_soft_limit": int(bool(f & _NEG_SOFT)),
        "max_soft_limit": int(bool(f & _POS_SOFT)),
        "min_hard_limit": int(bool(f & _NEG_HARD)),
        "max_hard_limit": int(bool(f & _POS_HARD)),
        "override_limits": int(override),
    }


def _gcodes(ctl: Any) -> tuple[int, ...]:
    """The reference's 17 active G-code slots (code x 10, -1: none)."""
    m = ctl.interp.modal
    return (ctl.interp.line, m.motion, -1, m.plane, m.cutter_comp, m.units,
            m.distance, m.feed_mode, m.coord_system, m.tool_length,
            m.retract, m.control, -1, 970, m.arc_distance, 80, -1)


def _mcodes(ctl: Any, flood: bool, mist: bool) -> tuple[int, ...]:
    """The reference's 10 active M-code slots (-1: none)."""
    m = ctl.interp.modal
    coolant = 9 if not (flood or mist) else 8 if flood else 7
    return (ctl.interp.line, -1, m.spindle // 10, -1, coolant, -1,
            48 if ctl.feed_override_enabled else 49, -1, -1, -1)


def build_snapshot(ctl: Any) -> dict:
    """The status fields of the machine of TaskController ``ctl``."""
    st = ctl.motion.status_dict()
    io = ctl.io
    table = io.table
    interp = ctl.interp
    ex = ctl.executor
    flood, mist = bool(io["coolant-flood"]), bool(io["coolant-mist"])
    n = max(0, min(st["num_joints"], len(st["joints"])))
    joints = st["joints"][:n]
    flags = [j["flags"] for j in joints]
    prepped = table.selected_pocket
    scales = ctl.spindle_scale
    spindles = [{
        "brake": int(bool(sp["brake"])), "direction": sp["direction"],
        "enabled": int(bool(sp["on"])), "override_enabled":
        bool(ctl.spindle_override_enabled[i]) if i < len(scales) else True,
        "speed": sp["speed"], "override": scales[i] if i < len(scales)
        else 1.0, "homed": False, "orient_state": int(sp["orient_state"]),
        "orient_fault": sp["orient_fault"]}
        for i, sp in enumerate(st["spindles"][:st["num_spindles"]])]
    axes = [{"velocity": a["vel_cmd"], "min_position_limit":
             a["min_pos_limit"], "max_position_limit": a["max_pos_limit"]}
            for a in st["axes"]]
    state = ctl.task.state
    num_dio = st["num_dio"]
    din, dout = st["din"], st["dout"]
    override = bool(st["override_limits"])
    return {
        "echo_serial_number": ctl.echo_serial,
        "state": ctl.echo_state,
        "task_state": int(state),
        "task_mode": int(ctl.task.mode),
        "task_paused": int(st["paused"] or ctl._m0_paused),
        "interp_state": int(ctl.task.interp_state),
        "exec_state": ctl.exec_state(),
        "interpreter_errcode": 0,
        "estop": int(state is TaskState.ESTOP),
        "file": ctl.file,
        "command": ctl.last_command,
        "ini_filename": ctl.ini_filename,
        "current_line": st["program_line"],
        "motion_line": st["program_line"],
        "read_line": interp.line,
        "call_level": ctl.call_level(),
        "queued_mdi_commands": len(ctl._mdi_queue),
        "optional_stop": ctl.optional_stop,
        "block_delete": ctl.block_delete,
        "input_timeout": type(ex.pending[0]).__name__ == "WaitInput"
        if ex.pending else False,
        "delay_left": ctl.delay_left(),
        "program_units": 2 if interp.program_metric else 1,
        "debug": ctl.debug,
        "gcodes": _gcodes(ctl),
        "mcodes": _mcodes(ctl, flood, mist),
        "settings": (float(interp.line), interp.feed, interp.speed, 0.0,
                     0.0),
        "g5x_index": ex.g5x_index,
        "g5x_offset": tuple(ex.g5x_offset),
        "g92_offset": tuple(ex.g92_offset),
        "rotation_xy": 0.0,
        "tool_offset": tuple(st["tool_offset"]),
        "enabled": st["enabled"],
        "inpos": st["in_position"],
        "paused": st["paused"],
        "motion_mode": _TRAJ_MODE.get(int(st["mode"]), 0),
        "motion_type": int(st["motion_type"]),
        "motion_id": st["motion_id"],
        "queue": st["queue_depth"],
        "active_queue": min(st["queue_depth"], 2),
        "queue_full": ctl.motion.queue_free() < 2,
        "position": tuple(st["carte_pos_cmd"]),
        "actual_position": tuple(st["carte_pos_fb"]),
        "probed_position": tuple(st["probed_pos"]),
        "dtg": (0.0,) * 9,
        "distance_to_go": st["distance_to_go"],
        "current_vel": st["current_vel"],
        "velocity": st["current_vel"],
        "acceleration": st["acc_limit"],
        "max_velocity": st["vel_limit"],
        "max_acceleration": st["acc_limit"],
        "feedrate": ctl.feed_scale,
        "rapidrate": st["rapid_scale"],
        "feed_override_enabled": ctl.feed_override_enabled,
        "feed_hold_enabled": st["feed_hold_enabled"],
        "adaptive_feed_enabled": st["adaptive_enabled"],
        "probing": st["probing"],
        "probe_tripped": st["probe_tripped"],
        "probe_val": int(st["probe_tripped"]),
        "kinematics_type": int(st["kins_type"]),
        "joints": st["num_joints"],
        "axes": 9,
        "axis_mask": ctl.axis_mask,
        "spindles": st["num_spindles"],
        "num_extrajoints": st["num_extrajoints"],
        "cycle_time": st["servo_period"],
        "linear_units": 1.0 if ctl.units == "mm" else 1 / 25.4,
        "angular_units": 1.0,
        "joint_position": tuple(j["pos_cmd"] for j in joints),
        "joint_actual_position": tuple(j["pos_fb"] for j in joints),
        "homed": tuple(int(bool(f & _HOMED)) for f in flags),
        "limit": tuple(_limit_mask(f) for f in flags),
        "din": tuple((din >> i) & 1 for i in range(num_dio)),
        "dout": tuple((dout >> i) & 1 for i in range(num_dio)),
        "ain": tuple(st["ain"]),
        "aout": tuple(st["aout"]),
        "mist": int(mist),
        "flood": int(flood),
        "lube": int(bool(io["lube"])),
        "lube_level": int(bool(io["lube_level"])),
        "tool_in_spindle": table.tool_in_spindle,
        "tool_from_pocket": int(io["tool-from-pocket"]),
        "pocket_prepped": -1 if prepped is None else prepped,
        "heartbeat": ctl.heartbeat,
        "task_pid": os.getpid(),
        "tool_changes": io.changes,
        "closed": False,
        "joint": [_joint_dict(j, override) for j in joints],
        "axis": axes,
        "spindle": spindles,
    }
