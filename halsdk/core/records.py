"""Records of a listing: copies of HAL objects taken in one pass.

:func:`halsdk.core._core.snapshot` copies every object of a kind, with
its metadata and value, under the instance lock in one pass; these are
the records it returns.  Unlike a handle (:class:`halsdk.Pin`, ...) a
record never changes and never goes stale: a listing made of records is
a consistent picture of the instance at one moment, whatever other
processes load or unload meanwhile.
"""

from __future__ import annotations

from typing import NamedTuple, Optional, Union

Value = Union[bool, int, float]


class ComponentInfo(NamedTuple):
    name: str
    id: int
    realtime: bool
    ready: bool
    pid: int
    alive: bool
    #: the host marked it dead: its process ended without removing it
    dead: bool = False


class InstanceInfo(NamedTuple):
    name: str
    id: int
    owner: str


class PinInfo(NamedTuple):
    name: str
    type: int
    direction: int
    value: Value
    owner: str
    owner_id: int
    signal: Optional[str]       #: the signal it is linked to, or None
    alias_of: Optional[str]     #: the original name while aliased


class ParamInfo(NamedTuple):
    name: str
    type: int
    direction: int
    value: Value
    owner: str
    owner_id: int
    alias_of: Optional[str]


class LinkedPin(NamedTuple):
    name: str
    direction: int


class SignalInfo(NamedTuple):
    name: str
    type: int
    value: Value
    pins: tuple[LinkedPin, ...]     #: in creation order
    readers: int
    writers: int
    bidirs: int


class FunctionInfo(NamedTuple):
    name: str
    owner: str
    owner_id: int
    uses_fp: bool
    reentrant: bool
    users: int
    realtime: bool
    time: int
    tmax: int


class ThreadInfo(NamedTuple):
    name: str
    period: int
    uses_fp: bool
    running: bool
    functions: tuple[str, ...]      #: in call order
    time: int
    tmax: int
    cycles: int
    overruns: int


class StreamInfo(NamedTuple):
    name: str
    owner: str


Record = Union[ComponentInfo, InstanceInfo, PinInfo, ParamInfo, SignalInfo,
               FunctionInfo, ThreadInfo, StreamInfo]

__all__ = ["ComponentInfo", "InstanceInfo", "PinInfo", "ParamInfo",
           "LinkedPin", "SignalInfo", "FunctionInfo", "ThreadInfo",
           "StreamInfo", "Record"]
