"""The fields of the machine's status channel: one table, used by the
task that publishes the snapshot and by every client that reads it.

The names are those of the reference's ``linuxcnc.stat`` attributes
(the Python Interface chapter of its manual), plus a few of halsdk's own
(marked below).  Each field has a kind and a count:

======== ===========================================================
kind     what a reader gets
======== ===========================================================
``i``    int (64-bit signed in the channel)
``b``    bool
``d``    float
``s``    str (UTF-8, at most ``count`` bytes in the channel)
======== ===========================================================

A count above 1 (for ``i``, ``b``, ``d``) gives a tuple of that length.
The per-joint, per-axis and per-spindle dictionaries and the tool table
are described by :data:`JOINT_FIELDS`, :data:`AXIS_FIELDS`,
:data:`SPINDLE_FIELDS` and :data:`TOOL_FIELDS`.

:data:`LAYOUT_VERSION` changes whenever this table changes, so that a
client built from another table is refused instead of reading garbage.
"""

from __future__ import annotations

__all__ = ["FIELDS", "JOINT_FIELDS", "AXIS_FIELDS", "SPINDLE_FIELDS",
           "TOOL_FIELDS", "MAX_JOINTS", "MAX_AXES", "MAX_SPINDLES",
           "MAX_TOOLS", "MAX_DIO", "MAX_AIO", "LAYOUT_VERSION",
           "STRING_SIZE"]

MAX_JOINTS = 16         #: the reference's EMCMOT_MAX_JOINTS
MAX_AXES = 9            #: X Y Z A B C U V W
MAX_SPINDLES = 8        #: the reference's EMCMOT_MAX_SPINDLES
MAX_DIO = 64            #: the reference's EMCMOT_MAX_DIO
MAX_AIO = 64            #: the reference's EMCMOT_MAX_AIO
MAX_TOOLS = 1000        #: the reference's CANON_POCKETS_MAX
STRING_SIZE = 1024      #: file names and the command line

#: (name, kind, count) of the top-level fields, in channel order
FIELDS: tuple[tuple[str, str, int], ...] = (
    # -- the command echo
    ("echo_serial_number", "i", 1),
    ("state", "i", 1),                  # RCS_DONE, RCS_EXEC, RCS_ERROR
    # -- task
    ("task_state", "i", 1),
    ("task_mode", "i", 1),
    ("task_paused", "i", 1),
    ("interp_state", "i", 1),
    ("exec_state", "i", 1),
    ("interpreter_errcode", "i", 1),
    ("estop", "i", 1),
    ("file", "s", STRING_SIZE),
    ("command", "s", STRING_SIZE),
    ("ini_filename", "s", STRING_SIZE),
    ("current_line", "i", 1),
    ("motion_line", "i", 1),
    ("read_line", "i", 1),
    ("call_level", "i", 1),
    ("queued_mdi_commands", "i", 1),
    ("optional_stop", "b", 1),
    ("block_delete", "b", 1),
    ("input_timeout", "b", 1),
    ("delay_left", "d", 1),
    ("program_units", "i", 1),          # 1 inch, 2 mm, 3 cm
    ("debug", "i", 1),
    ("misc_error", "i", 64),
    # -- the interpreter's modal state
    ("gcodes", "i", 17),
    ("mcodes", "i", 10),
    ("settings", "d", 5),
    ("g5x_index", "i", 1),
    ("g5x_offset", "d", 9),
    ("g92_offset", "d", 9),
    ("rotation_xy", "d", 1),
    ("tool_offset", "d", 9),
    # -- the trajectory level
    ("enabled", "b", 1),
    ("inpos", "b", 1),
    ("paused", "b", 1),
    ("motion_mode", "i", 1),            # TRAJ_MODE_*
    ("motion_type", "i", 1),
    ("motion_id", "i", 1),
    ("queue", "i", 1),
    ("active_queue", "i", 1),
    ("queue_full", "b", 1),
    ("position", "d", 9),
    ("actual_position", "d", 9),
    ("probed_position", "d", 9),
    ("dtg", "d", 9),
    ("distance_to_go", "d", 1),
    ("current_vel", "d", 1),
    ("velocity", "d", 1),
    ("acceleration", "d", 1),
    ("max_velocity", "d", 1),
    ("max_acceleration", "d", 1),
    ("feedrate", "d", 1),
    ("rapidrate", "d", 1),
    ("feed_override_enabled", "b", 1),
    ("feed_hold_enabled", "b", 1),
    ("adaptive_feed_enabled", "b", 1),
    ("probing", "b", 1),
    ("probe_tripped", "b", 1),
    ("probe_val", "i", 1),
    ("kinematics_type", "i", 1),
    ("joints", "i", 1),
    ("axes", "i", 1),
    ("axis_mask", "i", 1),
    ("spindles", "i", 1),
    ("num_extrajoints", "i", 1),
    ("cycle_time", "d", 1),
    ("linear_units", "d", 1),
    ("angular_units", "d", 1),
    ("joint_position", "d", MAX_JOINTS),
    ("joint_actual_position", "d", MAX_JOINTS),
    ("homed", "i", MAX_JOINTS),
    ("limit", "i", MAX_JOINTS),
    # -- I/O
    ("din", "i", MAX_DIO),
    ("dout", "i", MAX_DIO),
    ("ain", "d", MAX_AIO),
    ("aout", "d", MAX_AIO),
    ("mist", "i", 1),
    ("flood", "i", 1),
    ("lube", "i", 1),
    ("lube_level", "i", 1),
    ("tool_in_spindle", "i", 1),
    ("tool_from_pocket", "i", 1),
    ("pocket_prepped", "i", 1),
    # -- halsdk's own
    ("heartbeat", "i", 1),              # task cycles since the start
    ("task_pid", "i", 1),               # the process hosting the task
    ("tool_changes", "i", 1),           # tool changes since the start
    ("closed", "b", 1),                 # the task has stopped
)

#: the keys of each ``joint`` dictionary, as in the reference
JOINT_FIELDS: tuple[tuple[str, str], ...] = (
    ("jointType", "i"), ("units", "d"), ("backlash", "d"),
    ("min_position_limit", "d"), ("max_position_limit", "d"),
    ("max_ferror", "d"), ("min_ferror", "d"), ("ferror_current", "d"),
    ("ferror_highmark", "d"), ("output", "d"), ("input", "d"),
    ("velocity", "d"), ("inpos", "i"), ("homing", "i"), ("homed", "i"),
    ("fault", "i"), ("enabled", "i"), ("min_soft_limit", "i"),
    ("max_soft_limit", "i"), ("min_hard_limit", "i"),
    ("max_hard_limit", "i"), ("override_limits", "i"),
)

#: the keys of each ``axis`` dictionary
AXIS_FIELDS: tuple[tuple[str, str], ...] = (
    ("velocity", "d"), ("min_position_limit", "d"),
    ("max_position_limit", "d"),
)

#: the keys of each ``spindle`` dictionary
SPINDLE_FIELDS: tuple[tuple[str, str], ...] = (
    ("brake", "i"), ("direction", "i"), ("enabled", "i"),
    ("override_enabled", "b"), ("speed", "d"), ("override", "d"),
    ("homed", "b"), ("orient_state", "i"), ("orient_fault", "i"),
)

#: the fields of a tool table entry: the reference's ``tool_result``
#: (id to orientation), then halsdk's pocket and comment
TOOL_FIELDS: tuple[tuple[str, str], ...] = (
    ("id", "i"), ("xoffset", "d"), ("yoffset", "d"), ("zoffset", "d"),
    ("aoffset", "d"), ("boffset", "d"), ("coffset", "d"),
    ("uoffset", "d"), ("voffset", "d"), ("woffset", "d"),
    ("diameter", "d"), ("frontangle", "d"), ("backangle", "d"),
    ("orientation", "i"), ("pocket", "i"), ("comment", "s"),
)
TOOL_COMMENT_SIZE = 128

LAYOUT_VERSION = 1
