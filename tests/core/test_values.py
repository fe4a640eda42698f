"""The one value parser (halsdk.values) against the C library itself:
what it reads must be what C's strtod/strtol/strtoul and a C assignment
give, as the reference's halcmd and halstreamer get it."""

from __future__ import annotations

import ctypes
import math

from hypothesis import given
from hypothesis import strategies as st

from halsdk.types import HalType
from halsdk.values import c_float, c_wrap, parse_word

libc = ctypes.CDLL(None)
libc.strtod.restype = ctypes.c_double
libc.strtod.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_char_p)]
libc.strtol.restype = ctypes.c_long
libc.strtol.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_char_p),
                        ctypes.c_int]
libc.strtoul.restype = ctypes.c_ulong
libc.strtoul.argtypes = libc.strtol.argtypes

C_TYPES = {HalType.S32: ctypes.c_int32, HalType.U32: ctypes.c_uint32,
           HalType.S64: ctypes.c_int64, HalType.U64: ctypes.c_uint64}


def c_strtod(word: str) -> float | None:
    """strtod of the whole word, None when it stops early."""
    raw = word.encode()
    buf = ctypes.create_string_buffer(raw)
    end = ctypes.c_char_p()
    value = libc.strtod(buf, ctypes.byref(end))
    used = ctypes.cast(end, ctypes.c_void_p).value - ctypes.addressof(buf)
    return value if raw and used == len(raw) else None


def c_assign(htype: HalType, word: str, base: int) -> int:
    """strtol/strtoul of the word, then assigned to the HAL type's C
    type."""
    conv = libc.strtol if htype in (HalType.S32, HalType.S64) \
        else libc.strtoul
    return C_TYPES[htype](conv(word.encode(), None, base)).value


floats = st.floats(allow_nan=False, width=64)
float_words = st.one_of(
    floats.map(repr), floats.map(float.hex), floats.map("{:e}".format),
    floats.map("{:.3f}".format),
    st.sampled_from(["inf", "-Infinity", "+INF", "nan", "-nan", "1e", "0x",
                     ".", "+.5", "1.e3", "0x.8p1", "1..2", "--1", "nan(12)"]),
    st.text(alphabet="0123456789+-.eExXpPabcfinNtyI", max_size=8))


@given(float_words)
def test_floats_read_as_strtod_reads_them(word):
    ours, theirs = c_float(word), c_strtod(word)
    if theirs is None:
        assert ours is None, word
    elif math.isnan(theirs):
        assert ours is not None and math.isnan(ours), word
    else:
        assert ours == theirs, word


big = st.integers(min_value=-(1 << 70), max_value=1 << 70)


@given(st.sampled_from(list(C_TYPES)), big)
def test_integers_wrap_as_c_assigns_them(htype, v):
    """Decimal words, as halstreamer reads them (base 10)."""
    assert c_wrap(htype, v) == c_assign(htype, str(v), 10)


@given(st.sampled_from(list(C_TYPES)), big,
       st.sampled_from(["{:d}", "{:#x}", "{:#o}"]))
def test_halcmd_words_read_as_strtol_base_0(htype, v, form):
    """halcmd's setp words: strtol(word, 0) (hex, octal, decimal)."""
    word = form.format(v).replace("0o", "0")
    if word.startswith("-0o"):
        word = "-0" + word[3:]
    assert parse_word(htype, word) == c_assign(htype, word, 0)
