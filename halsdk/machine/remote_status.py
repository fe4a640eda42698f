"""The status of a running machine as the native client gives it:
:class:`RemoteStatus` (a frozen dataclass of the status channel's
snapshot, typed) with its joints, axes and spindles."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from halsdk.channels.constants import (
    EXEC_DONE,
    EXEC_ERROR,
    EXEC_WAITING_FOR_DELAY,
    EXEC_WAITING_FOR_IO,
    EXEC_WAITING_FOR_MOTION,
    EXEC_WAITING_FOR_MOTION_QUEUE,
)
from halsdk.channels.shmchannel import Snapshot, ToolResult
from halsdk.errors import InvalidError
from halsdk.machine.task import InterpState, TaskMode, TaskState

__all__ = ["RemoteStatus", "RemoteJoint", "RemoteAxis", "RemoteSpindle",
           "exec_state_name", "AXIS_LETTERS"]

#: the axes in the order of the status channel's tuples
AXIS_LETTERS = "XYZABCUVW"

_EXEC_NAMES = {EXEC_ERROR: "ERROR", EXEC_DONE: "DONE",
               EXEC_WAITING_FOR_MOTION: "WAITING_FOR_MOTION",
               EXEC_WAITING_FOR_MOTION_QUEUE: "WAITING_FOR_MOTION_QUEUE",
               EXEC_WAITING_FOR_IO: "WAITING_FOR_IO",
               EXEC_WAITING_FOR_DELAY: "WAITING_FOR_DELAY"}

def exec_state_name(state: int) -> str:
    """The name of the reference's EXEC_* number (``"DONE"``, ...)."""
    return _EXEC_NAMES.get(state, str(state))


def enum_member(cls: Any, value: Any, what: str) -> Any:
    """``value`` (a member, its number or its name) as a member of the
    IntEnum ``cls``; InvalidError naming the choices."""
    try:
        if isinstance(value, str):
            return cls[value.strip().upper().replace("-", "_")]
        return cls(value)
    except (KeyError, ValueError):
        choices = ", ".join(f"{m.name} ({m.value})" for m in cls)
        raise InvalidError(f"{what} {value!r}: expected one of "
                           f"{choices}") from None


# ---------------------------------------------------------------- status

@dataclass(frozen=True)
class RemoteJoint:
    """One joint of :attr:`RemoteStatus.joints` (the reference's
    ``stat.joint[i]`` dictionary, with typed names)."""
    index: int
    homed: bool
    homing: bool
    enabled: bool
    fault: bool
    inpos: bool
    position: float             #: commanded (the reference's ``output``)
    actual_position: float      #: feedback (``input``)
    velocity: float
    ferror: float               #: ``ferror_current``
    ferror_highmark: float
    backlash: float
    min_position_limit: float
    max_position_limit: float
    min_soft_limit: bool        #: on the soft limits, the hard limits
    max_soft_limit: bool
    min_hard_limit: bool
    max_hard_limit: bool
    override_limits: bool


@dataclass(frozen=True)
class RemoteAxis:
    """One axis in use (``[TRAJ]COORDINATES``) of
    :attr:`RemoteStatus.axes`."""
    name: str                   #: "X", "Y", ...
    velocity: float
    min_position_limit: float
    max_position_limit: float


@dataclass(frozen=True)
class RemoteSpindle:
    """One spindle of :attr:`RemoteStatus.spindles`."""
    index: int
    direction: int              #: 1 forward, -1 reverse, 0 stopped
    speed: float
    enabled: bool
    brake: bool
    override: float
    override_enabled: bool
    homed: bool
    orient_state: int
    orient_fault: int


Floats = tuple[float, ...]


@dataclass(frozen=True)
class RemoteStatus:
    """The status of a running machine, read by
    :meth:`MachineClient.status`: the reference's ``linuxcnc.stat``
    attributes that halsdk has, typed.

    Positions (``position``, ``g5x_offset`` ...) are 9-tuples in the
    order X Y Z A B C U V W; ``joint_position``, ``homed``, ``limit`` and
    ``joints`` hold one entry per joint of the machine, ``axes`` one per
    axis in use, ``spindles`` one per spindle.  Two statuses compare
    equal when everything but ``heartbeat`` is equal.
    """
    task_state: TaskState
    task_mode: TaskMode
    interp_state: InterpState
    exec_state: int             #: EXEC_* (:func:`exec_state_name`)
    estop: bool
    enabled: bool
    paused: bool                #: feed hold, pause or M0/M1
    inpos: bool
    file: str
    current_line: int
    motion_line: int
    read_line: int
    call_level: int
    command: str                #: the last MDI line
    queued_mdi_commands: int
    position: Floats            #: commanded, machine coordinates
    actual_position: Floats
    probed_position: Floats
    dtg: Floats
    distance_to_go: float
    current_vel: float
    joint_position: Floats
    joint_actual_position: Floats
    g5x_index: int
    g5x_offset: Floats
    g92_offset: Floats
    rotation_xy: float
    tool_offset: Floats
    homed: tuple[bool, ...]
    limit: tuple[int, ...]      #: bits: 1 min hard, 2 max hard, 4/8 soft
    joints: tuple[RemoteJoint, ...]
    axes: tuple[RemoteAxis, ...]
    spindles: tuple[RemoteSpindle, ...]
    feedrate: float             #: feed override scale
    rapidrate: float            #: rapid override scale
    max_velocity: float
    max_acceleration: float
    feed_override_enabled: bool
    feed_hold_enabled: bool
    adaptive_feed_enabled: bool
    motion_mode: int            #: TRAJ_MODE_*: 1 free, 2 coord, 3 teleop
    motion_type: int
    queue: int
    queue_full: bool
    probing: bool
    probe_tripped: bool
    mist: bool
    flood: bool
    lube: bool
    tool_in_spindle: int
    pocket_prepped: int
    tool_from_pocket: int
    tool_changes: int
    tool_table: tuple[ToolResult, ...]
    din: tuple[bool, ...]
    dout: tuple[bool, ...]
    ain: Floats
    aout: Floats
    gcodes: tuple[int, ...]
    mcodes: tuple[int, ...]
    settings: Floats
    optional_stop: bool
    block_delete: bool
    program_units: int          #: 1 inch, 2 mm, 3 cm
    linear_units: float
    angular_units: float
    cycle_time: float
    axis_mask: int
    kinematics_type: int
    ini_filename: str
    echo_serial_number: int     #: the task's latest command (any client)
    echo_state: int             #: its RCS_* (the reference's ``state``)
    task_pid: int
    errors_pending: int         #: messages this client has not taken
    heartbeat: int = field(compare=False)   #: task cycles so far

    # -- conveniences --------------------------------------------------

    @property
    def axis_names(self) -> str:
        """The letters of the axes in use, e.g. ``"XYZ"``."""
        return "".join(a.name for a in self.axes)

    @property
    def all_homed(self) -> bool:
        """Whether every joint is homed."""
        return bool(self.homed) and all(self.homed)

    # -- conversions ---------------------------------------------------

    @classmethod
    def from_snapshot(cls, snap: Snapshot, errors_pending: int = 0
                      ) -> RemoteStatus:
        """The status of a status channel :class:`Snapshot`."""
        d = snap.as_dict()
        nj = max(0, min(int(d["joints"]), len(d["joint"])))
        ns = max(0, min(int(d["spindles"]), len(d["spindle"])))
        mask = int(d["axis_mask"])
        joints = tuple(_joint(i, j) for i, j in enumerate(d["joint"][:nj]))
        axes = tuple(RemoteAxis(AXIS_LETTERS[i], float(a["velocity"]),
                                float(a["min_position_limit"]),
                                float(a["max_position_limit"]))
                     for i, a in enumerate(d["axis"]) if mask & (1 << i))
        spindles = tuple(_spindle(i, s)
                         for i, s in enumerate(d["spindle"][:ns]))
        return cls(
            task_state=_known(TaskState, d["task_state"], TaskState.ESTOP),
            task_mode=_known(TaskMode, d["task_mode"], TaskMode.MANUAL),
            interp_state=_known(InterpState, d["interp_state"],
                                InterpState.IDLE),
            exec_state=d["exec_state"], estop=bool(d["estop"]),
            enabled=d["enabled"], paused=bool(d["task_paused"]),
            inpos=d["inpos"], file=d["file"],
            current_line=d["current_line"], motion_line=d["motion_line"],
            read_line=d["read_line"], call_level=d["call_level"],
            command=d["command"],
            queued_mdi_commands=d["queued_mdi_commands"],
            position=d["position"], actual_position=d["actual_position"],
            probed_position=d["probed_position"], dtg=d["dtg"],
            distance_to_go=d["distance_to_go"],
            current_vel=d["current_vel"],
            joint_position=d["joint_position"][:nj],
            joint_actual_position=d["joint_actual_position"][:nj],
            g5x_index=d["g5x_index"], g5x_offset=d["g5x_offset"],
            g92_offset=d["g92_offset"], rotation_xy=d["rotation_xy"],
            tool_offset=d["tool_offset"],
            homed=tuple(bool(h) for h in d["homed"][:nj]),
            limit=d["limit"][:nj], joints=joints, axes=axes,
            spindles=spindles, feedrate=d["feedrate"],
            rapidrate=d["rapidrate"], max_velocity=d["max_velocity"],
            max_acceleration=d["max_acceleration"],
            feed_override_enabled=d["feed_override_enabled"],
            feed_hold_enabled=d["feed_hold_enabled"],
            adaptive_feed_enabled=d["adaptive_feed_enabled"],
            motion_mode=d["motion_mode"], motion_type=d["motion_type"],
            queue=d["queue"], queue_full=d["queue_full"],
            probing=d["probing"], probe_tripped=d["probe_tripped"],
            mist=bool(d["mist"]), flood=bool(d["flood"]),
            lube=bool(d["lube"]), tool_in_spindle=d["tool_in_spindle"],
            pocket_prepped=d["pocket_prepped"],
            tool_from_pocket=d["tool_from_pocket"],
            tool_changes=d["tool_changes"], tool_table=d["tool_table"],
            din=tuple(bool(v) for v in d["din"]),
            dout=tuple(bool(v) for v in d["dout"]),
            ain=d["ain"], aout=d["aout"], gcodes=d["gcodes"],
            mcodes=d["mcodes"], settings=d["settings"],
            optional_stop=d["optional_stop"],
            block_delete=d["block_delete"],
            program_units=d["program_units"],
            linear_units=d["linear_units"],
            angular_units=d["angular_units"], cycle_time=d["cycle_time"],
            axis_mask=mask, kinematics_type=d["kinematics_type"],
            ini_filename=d["ini_filename"],
            echo_serial_number=d["echo_serial_number"],
            echo_state=d["state"], task_pid=d["task_pid"],
            errors_pending=errors_pending, heartbeat=d["heartbeat"])

    def as_dict(self) -> dict[str, Any]:
        """Plain values for JSON: numbers (the enums as their numbers, as
        in the reference), strings, lists, and dicts for the joints, axes,
        spindles and tool table entries.  :meth:`from_dict` reverses it."""
        return {f.name: _plain(getattr(self, f.name)) for f in fields(self)}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RemoteStatus:
        """The status of :meth:`as_dict` (e.g. parsed back from the JSON
        of ``halsdk ctl status --json``); enums by number or name."""
        names = {f.name for f in fields(cls)}
        missing = sorted(names - set(data))
        if missing:
            raise InvalidError(f"a status needs every field; missing: "
                               f"{', '.join(missing)}")
        values = {}
        for name in names:
            value = data[name]
            convert = _FROM_PLAIN.get(name)
            if convert is not None:
                value = convert(value)
            elif isinstance(value, list):
                value = tuple(value)
            values[name] = value
        return cls(**values)


def _known(cls: Any, value: int, default: Any) -> Any:
    try:
        return cls(value)
    except ValueError:
        return default      # an all-zero snapshot: before the first cycle


def _joint(index: int, j: Mapping[str, Any]) -> RemoteJoint:
    return RemoteJoint(
        index=index, homed=bool(j["homed"]), homing=bool(j["homing"]),
        enabled=bool(j["enabled"]), fault=bool(j["fault"]),
        inpos=bool(j["inpos"]), position=j["output"],
        actual_position=j["input"], velocity=j["velocity"],
        ferror=j["ferror_current"], ferror_highmark=j["ferror_highmark"],
        backlash=j["backlash"], min_position_limit=j["min_position_limit"],
        max_position_limit=j["max_position_limit"],
        min_soft_limit=bool(j["min_soft_limit"]),
        max_soft_limit=bool(j["max_soft_limit"]),
        min_hard_limit=bool(j["min_hard_limit"]),
        max_hard_limit=bool(j["max_hard_limit"]),
        override_limits=bool(j["override_limits"]))


def _spindle(index: int, s: Mapping[str, Any]) -> RemoteSpindle:
    return RemoteSpindle(
        index=index, direction=s["direction"], speed=s["speed"],
        enabled=bool(s["enabled"]), brake=bool(s["brake"]),
        override=s["override"], override_enabled=bool(s["override_enabled"]),
        homed=bool(s["homed"]), orient_state=s["orient_state"],
        orient_fault=s["orient_fault"])


def _plain(value: Any) -> Any:
    if isinstance(value, (TaskState, TaskMode, InterpState)):
        return int(value)
    if isinstance(value, ToolResult):
        return dict(value._asdict())
    if isinstance(value, (RemoteJoint, RemoteAxis, RemoteSpindle)):
        return {f.name: getattr(value, f.name) for f in fields(value)}
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def _tuple_of(cls: Any) -> Callable[[Any], tuple[Any, ...]]:
    return lambda items: tuple(cls(**item) for item in items)


_FROM_PLAIN: dict[str, Callable[[Any], Any]] = {
    "task_state": lambda v: enum_member(TaskState, v, "task_state"),
    "task_mode": lambda v: enum_member(TaskMode, v, "task_mode"),
    "interp_state": lambda v: enum_member(InterpState, v, "interp_state"),
    "joints": _tuple_of(RemoteJoint),
    "axes": _tuple_of(RemoteAxis),
    "spindles": _tuple_of(RemoteSpindle),
    "tool_table": _tuple_of(ToolResult),
}
