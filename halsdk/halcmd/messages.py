"""The reference halcmd's words for the rules the core enforces.

The core reports a broken rule as a :class:`halsdk.HalError` with
``rule``, ``kind`` and ``names`` (see :class:`halsdk.errors.Rule`);
halcmd says it as the reference does, from this one table.  A key is
``(command, rule, variant)``: the command group, the rule, and a variant
the command tells apart (the kind of the object not found, whether a
signal of ``net`` existed, ...; ``None`` when there is none).  A value is
``(hal_line, message)``: the line the reference's HAL library prints
(``HAL: ERROR: ...``, printed as it is) and the line(s) halcmd prints
with the ``file:line:`` prefix; either may be ``None``.  The format fields
are ``{n0}``, ``{n1}``, ``{n2}`` (the names, in the rule's order),
``{kind}`` and whatever the command adds (``{failed}``: "link failed").
A rule the table does not know is printed with the core's own message.
"""

from __future__ import annotations

from typing import Any, Optional

from halsdk.errors import HalError, Rule

R = Rule
Entry = tuple[Optional[str], Optional[str]]

_OR_IO = "signal '{n0}' already has output or I/O pin(s)"
_HAS_PIN = ("Signal '{n0}' can not add {pin_dir} pin '{n1}', it already "
            "has {other_dir} pin '{n2}'")

MESSAGES: dict[tuple[str, Rule, Optional[str]], Entry] = {
    # net
    ("net", R.NAME_IS_PIN, None): (
        None, "Signal name '{n0}' must not be the same as a pin.  Did you "
        "omit the signal name?"),
    ("net", R.NO_PINS, None): (
        None, "'net' requires at least one pin, none given"),
    ("net", R.NOT_FOUND, "pin"): (None, "Pin '{n0}' does not exist"),
    ("net", R.PIN_LINKED, None): (
        None, "Pin '{n0}' was already linked to signal '{n1}'"),
    ("net", R.TYPE_MISMATCH, "existing"): (
        None, "Signal '{n0}' of type '{sig_type}' cannot add pin '{n1}' of "
        "type '{pin_type}'"),
    ("net", R.TYPE_MISMATCH, "new"): (
        "type mismatch '{n1}' <- '{n0}'", "link failed"),
    ("net", R.SECOND_WRITER, "existing"): (None, _HAS_PIN),
    ("net", R.WRITER_AND_IO, "existing"): (None, _HAS_PIN),
    ("net", R.SECOND_WRITER, "new"): (_OR_IO, "link failed"),
    ("net", R.WRITER_AND_IO, "new"): (_OR_IO, "link failed"),
    ("net", R.LOCKED, "signal"): (
        "signal_new called while HAL is locked", None),
    ("net", R.LOCKED, "pin"): ("link called while HAL locked",
                               "link failed"),
    # linkps, linksp, linkpp
    ("link", R.LOCKED, None): ("link called while HAL locked", "{failed}"),
    ("link", R.NOT_FOUND, "pin"): ("pin '{n0}' not found", "{failed}"),
    ("link", R.NOT_FOUND, "signal"): ("signal '{n0}' not found",
                                      "{failed}"),
    ("link", R.TYPE_MISMATCH, None): ("type mismatch '{n1}' <- '{n0}'",
                                      "{failed}"),
    ("link", R.PIN_LINKED, None): (
        "pin '{n0}' is linked to '{n1}', cannot link to '{n2}'",
        "{failed}"),
    ("link", R.SECOND_WRITER, None): (_OR_IO, "{failed}"),
    ("link", R.WRITER_AND_IO, None): (_OR_IO, "{failed}"),
    ("unlinkp", R.LOCKED, None): ("unlink called while HAL locked",
                                  "unlink failed"),
    ("unlinkp", R.NOT_FOUND, None): ("pin '{n0}' not found",
                                     "unlink failed"),
    # values
    ("setp", R.NOT_FOUND, None): (
        None, "parameter or pin '{n0}' not found"),
    ("setp", R.RO_PARAM, None): (None, "param '{n0}' is not writable"),
    ("setp", R.WRITE_OUTPUT, None): (None, "pin '{n0}' is not writable"),
    ("setp", R.PIN_CONNECTED, None): (
        None, "pin '{n0}' is connected to a signal"),
    ("setp", R.BAD_VALUE, None): (None, "value '{value}' invalid for "
                                  "{type_word}\nsetp failed"),
    ("sets", R.NOT_FOUND, None): (None, "signal '{n0}' not found"),
    ("sets", R.SIG_HAS_WRITER, None): (
        None, "signal '{n0}' already has writer(s)"),
    ("sets", R.BAD_VALUE, None): (None, "value '{value}' invalid for "
                                  "{type_word}\nsets failed"),
    ("getp", R.NOT_FOUND, None): (None, "pin or parameter '{n0}' not found"),
    ("gets", R.NOT_FOUND, None): (None, "signal '{n0}' not found"),
    # signals
    ("newsig", R.LOCKED, None): ("signal_new called while HAL is locked",
                                 "newsig failed"),
    ("newsig", R.EXISTS, None): ("duplicate signal '{n0}'",
                                 "newsig failed"),
    ("delsig", R.LOCKED, None): ("signal_delete called while HAL locked",
                                 None),
    ("delsig", R.NOT_FOUND, None): ("signal '{n0}' not found", None),
    # threads
    ("addf", R.LOCKED, None): (
        "add_funct_to_thread called while HAL is locked", "addf failed"),
    ("addf", R.NOT_FOUND, "function"): ("function '{n0}' not found",
                                        "addf failed"),
    ("addf", R.NOT_FOUND, "thread"): ("thread '{n0}' not found",
                                      "addf failed"),
    ("addf", R.BAD_POSITION, None): (
        "position '{position}' is too {high_low}", "addf failed"),
    ("delf", R.LOCKED, None): (
        "del_funct_from_thread called while HAL is locked", "delf failed"),
    ("delf", R.NOT_FOUND, "function"): ("function '{n0}' not found",
                                        "delf failed"),
    ("delf", R.FUNCT_UNUSED, None): ("function '{n0}' is not in use",
                                     "delf failed"),
    ("delf", R.NOT_FOUND, "thread"): ("thread '{n0}' not found",
                                      "delf failed"),
    ("start", R.LOCKED, None): (
        "start_threads called while HAL is locked", None),
    ("stop", R.LOCKED, None): (
        "stop_threads called while HAL is locked", None),
    # aliases
    ("alias", R.LOCKED, None): ("{kind}_alias called while HAL locked",
                                "alias failed"),
    ("alias", R.NOT_FOUND, None): ("{kind} '{n0}' not found",
                                   "alias failed"),
    ("alias", R.EXISTS, None): ("duplicate pin/alias name '{n0}'",
                                "alias failed"),
    ("unalias", R.NOT_FOUND, None): ("{kind} '{n0}' not found",
                                     "unalias failed"),
}


def lookup(command: str, exc: HalError,
           variant: Optional[str] = None) -> Optional[Entry]:
    """The table's entry for an error of ``command``: the variant's, else
    the one without variant, else None."""
    return (MESSAGES.get((command, exc.rule, variant))
            or MESSAGES.get((command, exc.rule, None)))


def words(entry: Entry, exc: HalError, **fields: Any) -> Entry:
    """The entry's lines filled in with the error's names and ``fields``."""
    names = list(exc.names) + ["", "", ""]
    values = {"n0": names[0], "n1": names[1], "n2": names[2],
              "kind": exc.kind or "", **fields}
    hal_line, message = entry
    return (hal_line.format(**values) if hal_line is not None else None,
            message.format(**values) if message is not None else None)
