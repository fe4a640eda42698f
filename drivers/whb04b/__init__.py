"""Userspace driver for the XHC WHB04B-6/-4 wireless USB jog pendant."""

from .driver import Whb04bDriver
from .fake import FakeBackend, ScriptError, load_script
from .protocol import (
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
