"""Message texts of the interpreter that the reference words per case.

The interpreter's error messages are the reference's (LinuxCNC's rs274)
texts, so a program refused by one is refused with the same words by the
other; :class:`~halsdk.gcode.errors.GCodeError` adds file:line:col.
"""

from __future__ import annotations

#: a word on a line with no code that uses it, by letter
UNUSED_WORD = {
    "d": "D word with no G41, G41.1, G42, G42.1, G71, G71.1, G71.2 or G96 "
         "to use it",
    "e": "E word with no G70, G76, M66, M67 or M68 to use it",
    "h": "H word with no G43 or G76 to use it",
    "i": "I word with no G2, G3, G5, G5.1, G10, G33.1, G76, or G87 to use "
         "it",
    "j": "J word with no G2, G3, G5, G5.1, G10, G76 or G87 to use it",
    "k": "K word with no G2, G3, G33, G33.1, G76, or G87 to use it",
    "l": "L word with no G10, cutter compensation, canned cycle, "
         "digital/analog input, M98 or NURBS code",
    "p": "P word with no G2 G3 G4 G10 G64 G5 G5.2 G76 G82 G86 G88 G89 or "
         "M50 M51 M52 M53 M62 M63 M64 M65 M66 M98 or user M code to use it",
    "q": "Q word with no G5, G10, G64, G73, G76, G83, M19, M66, M67, M68 or "
         "user M code that uses it",
    "r": "R word with no g code that uses it",
}

#: the plane of an arc as the reference names it (G17, G18, G19)
PLANE_NAME = {170: "xy", 180: "xz", 190: "yz"}


def unused_word(letter: str) -> str:
    """The message for a ``letter`` word no code of its line uses."""
    return UNUSED_WORD.get(letter, f"{letter.upper()} word with no G or M "
                                   "code to use it")


def arc_points(names: str, start: tuple[float, float],
               centre: tuple[float, float], end: tuple[float, float]) -> str:
    """``start=(X0.0000,Y0.0000) center=(...) end=(...)``: the points of
    an arc in program coordinates, the plane's two axes ``names``."""
    def point(p: tuple[float, float]) -> str:
        return f"({names[0]}{p[0]:.4f},{names[1]}{p[1]:.4f})"
    return (f"start={point(start)} center={point(centre)} "
            f"end={point(end)}")


def zero_radius_arc(names: str, start: tuple[float, float],
                    centre: tuple[float, float], end: tuple[float, float],
                    r1: float, r2: float) -> str:
    return (f"Zero-radius arc: {arc_points(names, start, centre, end)} "
            f"r1={r1:.4f} r2={r2:.4f}")


def arc_radius_differs(names: str, start: tuple[float, float],
                       centre: tuple[float, float], end: tuple[float, float],
                       r1: float, r2: float) -> str:
    err = abs(r1 - r2)
    return ("Radius to end of arc differs from radius to start: "
            f"{arc_points(names, start, centre, end)} r1={r1:.4f} "
            f"r2={r2:.4f} abs_err={err:.4g} "
            f"rel_err={err / max(r1, r2) * 100:.4f}%")
