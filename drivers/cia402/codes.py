"""Short texts for EMCY error codes (CiA 301/402 classes) and SDO abort
codes."""

from __future__ import annotations

#: EMCY error codes: exact codes first, then classes (see :func:`emcy_text`)
EMCY_TEXTS = {
    0x0000: "no error / error reset",
    0x1000: "generic error",
    0x2000: "current",
    0x2100: "current, device input side",
    0x2200: "current inside the device",
    0x2300: "current, device output side",
    0x2310: "continuous over-current",
    0x2320: "short circuit or earth leakage",
    0x3000: "voltage",
    0x3100: "mains voltage",
    0x3200: "voltage inside the device",
    0x3210: "DC link over-voltage",
    0x3220: "DC link under-voltage",
    0x3300: "output voltage",
    0x4000: "temperature",
    0x4100: "ambient temperature",
    0x4200: "device temperature",
    0x4300: "drive temperature",
    0x5000: "device hardware",
    0x6000: "device software",
    0x6100: "internal software",
    0x6200: "user software",
    0x6300: "data set",
    0x6320: "parameter error",
    0x7000: "additional modules",
    0x7100: "power",
    0x7300: "sensor",
    0x7500: "communication module",
    0x8000: "monitoring",
    0x8100: "communication",
    0x8110: "CAN overrun, objects lost",
    0x8120: "CAN in error passive mode",
    0x8130: "life guard or heartbeat error",
    0x8140: "recovered from bus off",
    0x8200: "protocol error",
    0x8210: "PDO not processed, length error",
    0x8300: "torque control",
    0x8400: "velocity or speed controller",
    0x8500: "position controller",
    0x8600: "positioning controller",
    0x8611: "following error",
    0x8612: "reference limit",
    0x9000: "external error",
    0xF000: "additional functions",
    0xFF00: "device specific",
}

#: SDO abort codes (CiA 301)
ABORT_TEXTS = {
    0x05030000: "toggle bit not alternated",
    0x05040000: "SDO protocol timed out",
    0x05040001: "command specifier not valid or unknown",
    0x05040005: "out of memory",
    0x06010000: "unsupported access to the object",
    0x06010001: "attempt to read a write-only object",
    0x06010002: "attempt to write a read-only object",
    0x06020000: "object does not exist in the object dictionary",
    0x06040041: "object cannot be mapped to a PDO",
    0x06040042: "mapped objects exceed the PDO length",
    0x06040043: "general parameter incompatibility",
    0x06040047: "general internal incompatibility in the device",
    0x06060000: "access failed because of a hardware error",
    0x06070010: "data type or length does not match",
    0x06070012: "data type does not match, length too high",
    0x06070013: "data type does not match, length too low",
    0x06090011: "sub-index does not exist",
    0x06090030: "value out of range",
    0x06090031: "value too high",
    0x06090032: "value too low",
    0x08000000: "general error",
    0x08000020: "data cannot be transferred or stored",
    0x08000021: "data cannot be stored: local control",
    0x08000022: "data cannot be stored: present device state",
    0x08000024: "no data available",
}


def emcy_text(code: int) -> str:
    """The text of an EMCY error code: the exact code, else its class."""
    for mask in (0xFFFF, 0xFFF0, 0xFF00, 0xF000):
        text = EMCY_TEXTS.get(code & mask)
        if text is not None and (code & mask or code == 0):
            return text
    return "unknown error"


def abort_text(code: int) -> str:
    return ABORT_TEXTS.get(code, "unknown abort code")
