"""The CiA 402 drive state machine: statusword decoding and controlword
commands."""

from __future__ import annotations

#: values of the ``state`` pin
NO_DATA = -1
NOT_READY = 0
SWITCH_ON_DISABLED = 1
READY_TO_SWITCH_ON = 2
SWITCHED_ON = 3
OPERATION_ENABLED = 4
QUICK_STOP_ACTIVE = 5
FAULT_REACTION_ACTIVE = 6
FAULT = 7

STATE_NAMES = {
    NO_DATA: "no data", NOT_READY: "not ready to switch on",
    SWITCH_ON_DISABLED: "switch on disabled",
    READY_TO_SWITCH_ON: "ready to switch on", SWITCHED_ON: "switched on",
    OPERATION_ENABLED: "operation enabled",
    QUICK_STOP_ACTIVE: "quick stop active",
    FAULT_REACTION_ACTIVE: "fault reaction active", FAULT: "fault",
}

#: statusword patterns: (mask, value, state), checked in order
_PATTERNS = (
    (0x4F, 0x00, NOT_READY),
    (0x4F, 0x40, SWITCH_ON_DISABLED),
    (0x6F, 0x21, READY_TO_SWITCH_ON),
    (0x6F, 0x23, SWITCHED_ON),
    (0x6F, 0x27, OPERATION_ENABLED),
    (0x6F, 0x07, QUICK_STOP_ACTIVE),
    (0x4F, 0x0F, FAULT_REACTION_ACTIVE),
    (0x4F, 0x08, FAULT),
)

#: statusword bits
SW_TARGET_REACHED = 1 << 10
SW_SETPOINT_ACK = 1 << 12        # PP: set-point acknowledge
SW_FOLLOWING_ERROR = 1 << 13

#: controlword commands (bits 0-3, 7)
CW_SHUTDOWN = 0x0006
CW_SWITCH_ON = 0x0007
CW_ENABLE_OPERATION = 0x000F
CW_DISABLE_VOLTAGE = 0x0000
CW_QUICK_STOP = 0x0002
CW_DISABLE_OPERATION = 0x0007
CW_FAULT_RESET = 0x0080
CW_NEW_SETPOINT = 1 << 4         # PP
CW_CHANGE_IMMEDIATELY = 1 << 5   # PP
CW_RELATIVE = 1 << 6             # PP

#: modes of operation (object 0x6060)
MODE_PP = 1
MODE_CSP = 8
MODE_CSV = 9
MODES = {"pp": MODE_PP, "csp": MODE_CSP, "csv": MODE_CSV}


def decode(statusword: int) -> int:
    """The state (``NOT_READY`` … ``FAULT``) a statusword reports."""
    for mask, value, state in _PATTERNS:
        if statusword & mask == value:
            return state
    return NOT_READY


def command(state: int, enable: bool, quick_stop: bool) -> int:
    """Controlword bits 0-3 that move a drive in ``state`` towards
    operation enabled (``enable``), towards ready to switch on (not
    ``enable``) or into quick stop."""
    if state in (FAULT, FAULT_REACTION_ACTIVE, NOT_READY, NO_DATA):
        return CW_DISABLE_VOLTAGE
    if quick_stop:
        if state in (OPERATION_ENABLED, QUICK_STOP_ACTIVE):
            return CW_QUICK_STOP
        return CW_DISABLE_VOLTAGE
    if state == QUICK_STOP_ACTIVE:
        return CW_DISABLE_VOLTAGE        # leave quick stop: switch on disabled
    if not enable:
        return CW_SHUTDOWN
    if state == SWITCH_ON_DISABLED:
        return CW_SHUTDOWN
    if state == READY_TO_SWITCH_ON:
        return CW_SWITCH_ON
    return CW_ENABLE_OPERATION           # switched on, operation enabled
