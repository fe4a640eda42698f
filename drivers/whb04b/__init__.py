"""Userspace driver for the XHC WHB04B-6/-4 wireless USB jog pendant."""

from halsdk.drivers.whb04b.driver import Whb04bDriver
from halsdk.drivers.whb04b.fake import FakeBackend, ScriptError, load_script
from halsdk.drivers.whb04b.protocol import (
    BUTTON_NAMES,
    Report,
    ReportError,
    display_chunks,
    encode_display,
    parse_report,
)

__all__ = ["Whb04bDriver", "FakeBackend", "ScriptError", "load_script",
           "BUTTON_NAMES", "Report", "ReportError", "display_chunks",
           "encode_display", "parse_report"]
