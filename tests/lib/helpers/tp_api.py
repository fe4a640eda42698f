"""The table of tpmod (components/motion/tp.h, ``halsdk_tp_api_t``,
version 2) and its structures, in ctypes: the test of the planner and
bench/tp.py call tpmod through it, one planner cycle per call."""

from __future__ import annotations

import ctypes as C


class Cart(C.Structure):
    _fields_ = [("x", C.c_double), ("y", C.c_double), ("z", C.c_double)]


class Pose9(C.Structure):
    _fields_ = [("tran", Cart)] + [(n, C.c_double) for n in "abcuvw"]

    def values(self):
        t = self.tran
        return [t.x, t.y, t.z] + [getattr(self, n) for n in "abcuvw"]


def pose9(*v):
    v = list(v) + [0.0] * (9 - len(v))
    return Pose9(Cart(*v[:3]), *v[3:])


class Move(C.Structure):
    _fields_ = [("id", C.c_int), ("type", C.c_int), ("vel", C.c_double),
                ("ini_maxvel", C.c_double), ("acc", C.c_double),
                ("jerk", C.c_double), ("term_cond", C.c_int),
                ("tolerance", C.c_double), ("flags", C.c_uint),
                ("cam_tolerance", C.c_double), ("sync", C.c_int),
                ("spindle", C.c_int), ("pitch", C.c_double)]


class SpindleIn(C.Structure):
    _fields_ = [("revs", C.c_double), ("speed", C.c_double),
                ("at_speed", C.c_int), ("index_enable", C.c_int)]


TP_IN_FEED, TP_IN_SPINDLES = 1, 2


class Inputs(C.Structure):
    _fields_ = [("probe_input", C.c_int), ("spindle_revs", C.c_double),
                ("spindle_speed", C.c_double),
                ("spindle_at_speed", C.c_int),
                ("have", C.c_uint), ("feed_hold", C.c_int),
                ("feed_inhibit", C.c_int), ("adaptive_feed", C.c_double),
                ("spindle", SpindleIn * 8)]


class State(C.Structure):
    _fields_ = [("vel", C.c_double), ("acc", C.c_double),
                ("dtg", C.c_double), ("dtg_pose", Pose9),
                ("vel_pose", Pose9), ("exec_id", C.c_int),
                ("motion_type", C.c_int), ("queue_depth", C.c_int),
                ("done", C.c_int), ("paused", C.c_int),
                ("probing", C.c_int), ("requested_vel", C.c_double),
                ("active_moves", C.c_int), ("waiting", C.c_int),
                ("spindle_sync", C.c_int), ("rigid_tap_reversed", C.c_int),
                ("feed_scale", C.c_double)]


_F = C.CFUNCTYPE
_P = C.POINTER
_W = [C.c_char_p, C.c_int]


class TpApi(C.Structure):
    _fields_ = [
        ("version", C.c_int),
        ("init", _F(C.c_int, C.c_int, C.c_double, C.c_void_p, *_W)),
        ("set_vel_limit", _F(None, C.c_double)),
        ("set_axis_limits", _F(None, C.c_int, C.c_double, C.c_double)),
        ("set_pos", _F(C.c_int, _P(Pose9), *_W)),
        ("get_pos", _F(None, _P(Pose9))),
        ("add_line", _F(C.c_int, _P(Pose9), _P(Move), *_W)),
        ("add_circle", _F(C.c_int, _P(Pose9), _P(Cart), _P(Cart), C.c_int,
                          _P(Move), *_W)),
        ("add_probe", _F(C.c_int, _P(Pose9), _P(Move), C.c_int, *_W)),
        ("set_dout", _F(C.c_int, C.c_int, C.c_int, C.c_int)),
        ("set_aout", _F(C.c_int, C.c_int, C.c_double, C.c_int)),
        ("abort", _F(None)), ("pause", _F(None)), ("resume", _F(None)),
        ("step", _F(None)),
        ("set_scale", _F(None, C.c_double, C.c_double)),
        ("run_cycle", _F(None, _P(Inputs), _P(Pose9))),
        ("get_state", _F(None, _P(State))),
        ("is_done", _F(C.c_int)), ("queue_depth", _F(C.c_int)),
        ("queue_space", _F(C.c_int)), ("exec_id", _F(C.c_int)),
        ("distance_to_go", _F(C.c_double)),
        ("current_vel", _F(C.c_double)),
        ("probe_result", _F(C.c_int, _P(Pose9))),
        ("clear_probe", _F(None)),
        ("take_error", _F(C.c_char_p)),
        ("reset", _F(None)),
        ("add_rigid_tap", _F(C.c_int, _P(Pose9), _P(Move), *_W)),
    ]


class Hooks(C.Structure):
    _fields_ = [("set_dout", _F(None, C.c_int, C.c_int)),
                ("set_aout", _F(None, C.c_int, C.c_double)),
                ("index_enable", _F(None, C.c_int)),
                ("spindle_reverse", _F(None, C.c_int, C.c_int))]


#: term_cond of a move
STOP, EXACT, BLEND = 0, 1, 2
