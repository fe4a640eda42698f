# cython: language_level=3, boundscheck=False, wraparound=False
"""Low-level access to motmod's command channel (components/motion/
channel.h): the client lock, sending a command record, reading the echo,
a consistent status snapshot (seqlock) and the error message ring.

This module only moves bytes with the right memory ordering; waiting,
timeouts and decoding belong to :mod:`halsdk.motion.client`.
"""

from libc.stdint cimport int32_t, uint32_t, uint64_t, uintptr_t
from libc.stdlib cimport calloc, free
from libc.string cimport memcpy, memset

from halsdk.errors import InstanceError
from halsdk.hal import Hal

cdef extern from *:
    """
    #include <errno.h>
    #include <signal.h>
    static inline uint32_t mch_load32(volatile uint32_t *p)
    { return __atomic_load_n(p, __ATOMIC_ACQUIRE); }
    static inline uint64_t mch_load64(volatile uint64_t *p)
    { return __atomic_load_n(p, __ATOMIC_ACQUIRE); }
    static inline void mch_store32(volatile uint32_t *p, uint32_t v)
    { __atomic_store_n(p, v, __ATOMIC_RELEASE); }
    static inline void mch_store_i32(int32_t *p, int32_t v)
    { __atomic_store_n(p, v, __ATOMIC_RELEASE); }
    static inline int mch_cas_i32(int32_t *p, int32_t from, int32_t to)
    { return __atomic_compare_exchange_n(p, &from, to, 0, __ATOMIC_ACQ_REL,
                                         __ATOMIC_ACQUIRE); }
    static inline int32_t mch_load_i32(int32_t *p)
    { return __atomic_load_n(p, __ATOMIC_ACQUIRE); }
    static inline void mch_acquire(void)
    { __atomic_thread_fence(__ATOMIC_ACQUIRE); }
    static inline void mch_release(void)
    { __atomic_thread_fence(__ATOMIC_RELEASE); }
    static inline int mch_pid_dead(int pid)
    { return kill(pid, 0) < 0 && errno == ESRCH; }
    #include <sched.h>
    #include <time.h>
    static inline double mch_now(void)
    {
        struct timespec t;
        clock_gettime(CLOCK_MONOTONIC, &t);
        return t.tv_sec + 1e-9 * t.tv_nsec;
    }
    """
    uint32_t mch_load32(volatile uint32_t *p) nogil
    uint64_t mch_load64(volatile uint64_t *p) nogil
    void mch_store32(volatile uint32_t *p, uint32_t v) nogil
    void mch_store_i32(int32_t *p, int32_t v) nogil
    bint mch_cas_i32(int32_t *p, int32_t frm, int32_t to) nogil
    int32_t mch_load_i32(int32_t *p) nogil
    void mch_acquire() nogil
    void mch_release() nogil
    bint mch_pid_dead(int pid) nogil
    double mch_now() nogil
    int sched_yield() nogil

cdef extern from "halsdk_api.h":
    ctypedef struct halsdk_api:
        int version
        long long (*shmem_attach)(const char *name)
        void *(*shmem_ptr)(long long handle)
        long (*shmem_size)(long long handle)
    const halsdk_api *halsdk_api_ptr
    int import_halsdk() except -1

cdef extern from "emcpose.h":
    ctypedef struct PmCartesian:
        double x, y, z
    ctypedef struct EmcPose:
        PmCartesian tran
        double a, b, c, u, v, w

cdef extern from "channel.h":
    enum:
        MOT_CHANNEL_MAGIC
        MOT_CHANNEL_VERSION
        MOT_MAX_JOINTS
        MOT_MAX_AXES
        MOT_REASON_LEN
        MOT_MSG_LEN
        MOT_MSG_RING
        MOT_QUEUE_SIZE
        MOT_MAX_SPINDLES
        MOT_MAX_AIO

    # (the array sizes below are the headers' #defines)

    ctypedef struct mot_command_t:
        int32_t cmd, joint, axis, ival, index, id, motion_type, turn
        double vel, ini_maxvel, acc, jerk, offset, value
        double min_limit, max_limit, tolerance
        double comp[3]
        EmcPose pos
        PmCartesian center, normal
        double home_offset, home, home_search_vel, home_latch_vel
        double home_final_vel
        int32_t home_sequence, volatile_home
        uint32_t home_flags
        int32_t line
        uint32_t epoch
        int32_t sync
        double pitch

    ctypedef struct mot_spindle_status_t:
        double speed, speed_in, revs, orient_angle, css_factor
        int32_t on, direction, brake, locked, orient_state, orient_fault
        int32_t at_speed, inhibit, amp_fault

    ctypedef struct mot_joint_status_t:
        uint32_t flags
        int32_t home_state
        double pos_cmd, pos_fb, vel_cmd, acc_cmd, ferror, ferror_limit
        double ferror_high_mark, motor_offset, motor_pos_cmd, motor_pos_fb
        double backlash_filt, min_pos_limit, max_pos_limit, vel_limit
        double acc_limit, jerk_limit, min_ferror, max_ferror, backlash
        double free_target
        int32_t free_active, jog_active

    ctypedef struct mot_axis_status_t:
        double pos_cmd, vel_cmd, teleop_pos, teleop_vel, teleop_target
        double min_pos_limit, max_pos_limit, vel_limit, acc_limit
        double jerk_limit
        int32_t teleop_active, jog_active

    ctypedef struct mot_status_t:
        uint64_t heartbeat
        int32_t mode, enabled, in_position, on_soft_limit, override_limits
        int32_t num_joints, num_joints_loaded, num_extrajoints, kins_type
        int32_t homing, all_homed, paused, probing, probe_tripped
        int32_t queue_depth, motion_id, motion_type, profile, coord_error
        int32_t error, num_dio, num_aio, num_spindles, term_cond
        double feed_scale, rapid_scale, current_vel, distance_to_go
        double requested_vel, vel_limit, acc_limit, tolerance
        double servo_period, traj_period
        EmcPose carte_pos_cmd, carte_pos_fb
        int32_t carte_pos_fb_ok
        EmcPose probed_pos, tool_offset
        uint64_t dout, din
        mot_joint_status_t joint[MOT_MAX_JOINTS]
        mot_axis_status_t axis[MOT_MAX_AXES]
        int32_t program_line, feed_hold_enabled, adaptive_enabled
        int32_t feed_hold, feed_inhibit, queue_taken
        uint32_t queue_err_count
        double adaptive_feed, feed_upm, linear_units
        double ain[MOT_MAX_AIO]
        double aout[MOT_MAX_AIO]
        mot_spindle_status_t spindle[MOT_MAX_SPINDLES]
        int32_t spindle_wait, queue_held

    ctypedef struct mot_msg_t:
        uint64_t n
        char text[MOT_MSG_LEN]

    ctypedef struct mot_channel_t:
        uint32_t magic, version, size
        int32_t lock_pid
        uint32_t cmd_seq, echo_seq
        int32_t echo_status, echo_cmd
        char echo_reason[MOT_REASON_LEN]
        mot_command_t command
        uint32_t status_seq
        mot_status_t status
        uint64_t msg_count
        mot_msg_t msgs[MOT_MSG_RING]
        uint32_t q_head, q_tail, q_err_count
        int32_t q_err_cmd, q_err_id, q_err_line
        char q_err_reason[MOT_REASON_LEN]
        mot_command_t queue[MOT_QUEUE_SIZE]


# ------------------------------------------------------------ protocol
# The numbers of the protocol, taken from the headers when this module is
# compiled: halsdk.motion.protocol builds its enums from the dicts below
# (name without prefix -> value), so no number is typed twice.

cdef extern from "channel.h":
    enum:
        MOT_CMD_NONE
        MOT_CMD_ABORT
        MOT_CMD_FREE
        MOT_CMD_TELEOP
        MOT_CMD_COORD
        MOT_CMD_ENABLE
        MOT_CMD_DISABLE
        MOT_CMD_ENABLE_AMPLIFIER
        MOT_CMD_DISABLE_AMPLIFIER
        MOT_CMD_ACTIVATE_JOINT
        MOT_CMD_DEACTIVATE_JOINT
        MOT_CMD_PAUSE
        MOT_CMD_RESUME
        MOT_CMD_STEP
        MOT_CMD_SCALE
        MOT_CMD_RAPID_SCALE
        MOT_CMD_OVERRIDE_LIMITS
        MOT_CMD_HOME
        MOT_CMD_UNHOME
        MOT_CMD_JOG_CONT
        MOT_CMD_JOG_INCR
        MOT_CMD_JOG_ABS
        MOT_CMD_JOG_STOP
        MOT_CMD_SET_LINE
        MOT_CMD_SET_CIRCLE
        MOT_CMD_SET_TELEOP_VECTOR
        MOT_CMD_PROBE
        MOT_CMD_CLEAR_PROBE_FLAG
        MOT_CMD_SET_NUM_JOINTS
        MOT_CMD_SET_JOINT_POSITION_LIMITS
        MOT_CMD_SET_JOINT_VEL_LIMIT
        MOT_CMD_SET_JOINT_ACC_LIMIT
        MOT_CMD_SET_JOINT_JERK_LIMIT
        MOT_CMD_SET_JOINT_MIN_FERROR
        MOT_CMD_SET_JOINT_MAX_FERROR
        MOT_CMD_SET_JOINT_HOMING_PARAMS
        MOT_CMD_SET_JOINT_BACKLASH
        MOT_CMD_SET_JOINT_COMP
        MOT_CMD_CLEAR_JOINT_COMP
        MOT_CMD_SET_JOINT_MOTOR_OFFSET
        MOT_CMD_SET_AXIS_POSITION_LIMITS
        MOT_CMD_SET_AXIS_VEL_LIMIT
        MOT_CMD_SET_AXIS_ACC_LIMIT
        MOT_CMD_SET_AXIS_JERK_LIMIT
        MOT_CMD_SET_VEL
        MOT_CMD_SET_VEL_LIMIT
        MOT_CMD_SET_ACC
        MOT_CMD_SET_TERM_COND
        MOT_CMD_SET_OFFSET
        MOT_CMD_SET_PROFILE
        MOT_CMD_SET_DOUT
        MOT_CMD_SET_AOUT
        MOT_CMD_SET_FEED_HOLD_ENABLE
        MOT_CMD_SET_ADAPTIVE_FEED_ENABLE
        MOT_CMD_SET_LINEAR_UNITS
        MOT_CMD_SPINDLE_ON
        MOT_CMD_SPINDLE_OFF
        MOT_CMD_SPINDLE_INCREASE
        MOT_CMD_SPINDLE_DECREASE
        MOT_CMD_SPINDLE_ORIENT
        MOT_CMD_SPINDLE_BRAKE_ENGAGE
        MOT_CMD_SPINDLE_BRAKE_RELEASE
        MOT_CMD_SPINDLE_SYNC_LINE
        MOT_CMD_RIGID_TAP
        MOT_CMD_RESERVED_FIRST
        MOT_CMD_RESERVED_LAST
        MOT_CMD_LAST
        MOT_ECHO_NONE
        MOT_ECHO_DONE
        MOT_ECHO_ACCEPTED
        MOT_ECHO_REJECTED
        MOT_MODE_FREE
        MOT_MODE_TELEOP
        MOT_MODE_COORD
        MOT_TERM_STOP
        MOT_TERM_EXACT
        MOT_TERM_BLEND
        MOT_MOTION_NONE
        MOT_MOTION_TRAVERSE
        MOT_MOTION_FEED
        MOT_MOTION_ARC
        MOT_MOTION_TOOLCHANGE
        MOT_MOTION_PROBING
        MOT_MOTION_INDEXROTARY
        MOT_KINS_IDENTITY
        MOT_KINS_FORWARD_ONLY
        MOT_KINS_INVERSE_ONLY
        MOT_KINS_BOTH
        MOT_ORIENT_NONE
        MOT_ORIENT_RUNNING
        MOT_ORIENT_DONE
        MOT_ORIENT_FAULT
        MOT_PROBE_NO_ERROR
        MOT_PROBE_AWAY

cdef extern from "homing.h":
    enum:
        HOME_IGNORE_LIMITS
        HOME_USE_INDEX
        HOME_IS_SHARED
        HOME_UNLOCK_FIRST
        HOME_ABSOLUTE_ENCODER
        HOME_NO_REHOME
        HOME_NO_FINAL_MOVE
        HOME_INDEX_NO_ENCODER_RESET
        HOME_SEQUENCE_NONE

cdef extern from "mot_joint.h":
    enum:
        MOT_JOINT_ACTIVE
        MOT_JOINT_ENABLED
        MOT_JOINT_INPOS
        MOT_JOINT_ERROR
        MOT_JOINT_POS_SOFT
        MOT_JOINT_NEG_SOFT
        MOT_JOINT_POS_HARD
        MOT_JOINT_NEG_HARD
        MOT_JOINT_FERROR
        MOT_JOINT_FAULT
        MOT_JOINT_HOMING
        MOT_JOINT_HOMED

cdef extern from "freeplan.h":
    enum:
        FP_TRAPEZOID
        FP_JERK


# the names above, in dicts (name without its prefix -> value)
CMD = {"ABORT": MOT_CMD_ABORT, "FREE": MOT_CMD_FREE, "TELEOP": MOT_CMD_TELEOP,
       "COORD": MOT_CMD_COORD, "ENABLE": MOT_CMD_ENABLE,
       "DISABLE": MOT_CMD_DISABLE,
       "ENABLE_AMPLIFIER": MOT_CMD_ENABLE_AMPLIFIER,
       "DISABLE_AMPLIFIER": MOT_CMD_DISABLE_AMPLIFIER,
       "ACTIVATE_JOINT": MOT_CMD_ACTIVATE_JOINT,
       "DEACTIVATE_JOINT": MOT_CMD_DEACTIVATE_JOINT, "PAUSE": MOT_CMD_PAUSE,
       "RESUME": MOT_CMD_RESUME, "STEP": MOT_CMD_STEP, "SCALE": MOT_CMD_SCALE,
       "RAPID_SCALE": MOT_CMD_RAPID_SCALE,
       "OVERRIDE_LIMITS": MOT_CMD_OVERRIDE_LIMITS, "HOME": MOT_CMD_HOME,
       "UNHOME": MOT_CMD_UNHOME, "JOG_CONT": MOT_CMD_JOG_CONT,
       "JOG_INCR": MOT_CMD_JOG_INCR, "JOG_ABS": MOT_CMD_JOG_ABS,
       "JOG_STOP": MOT_CMD_JOG_STOP, "SET_LINE": MOT_CMD_SET_LINE,
       "SET_CIRCLE": MOT_CMD_SET_CIRCLE,
       "SET_TELEOP_VECTOR": MOT_CMD_SET_TELEOP_VECTOR, "PROBE": MOT_CMD_PROBE,
       "CLEAR_PROBE_FLAG": MOT_CMD_CLEAR_PROBE_FLAG,
       "SET_NUM_JOINTS": MOT_CMD_SET_NUM_JOINTS,
       "SET_JOINT_POSITION_LIMITS": MOT_CMD_SET_JOINT_POSITION_LIMITS,
       "SET_JOINT_VEL_LIMIT": MOT_CMD_SET_JOINT_VEL_LIMIT,
       "SET_JOINT_ACC_LIMIT": MOT_CMD_SET_JOINT_ACC_LIMIT,
       "SET_JOINT_JERK_LIMIT": MOT_CMD_SET_JOINT_JERK_LIMIT,
       "SET_JOINT_MIN_FERROR": MOT_CMD_SET_JOINT_MIN_FERROR,
       "SET_JOINT_MAX_FERROR": MOT_CMD_SET_JOINT_MAX_FERROR,
       "SET_JOINT_HOMING_PARAMS": MOT_CMD_SET_JOINT_HOMING_PARAMS,
       "SET_JOINT_BACKLASH": MOT_CMD_SET_JOINT_BACKLASH,
       "SET_JOINT_COMP": MOT_CMD_SET_JOINT_COMP,
       "CLEAR_JOINT_COMP": MOT_CMD_CLEAR_JOINT_COMP,
       "SET_JOINT_MOTOR_OFFSET": MOT_CMD_SET_JOINT_MOTOR_OFFSET,
       "SET_AXIS_POSITION_LIMITS": MOT_CMD_SET_AXIS_POSITION_LIMITS,
       "SET_AXIS_VEL_LIMIT": MOT_CMD_SET_AXIS_VEL_LIMIT,
       "SET_AXIS_ACC_LIMIT": MOT_CMD_SET_AXIS_ACC_LIMIT,
       "SET_AXIS_JERK_LIMIT": MOT_CMD_SET_AXIS_JERK_LIMIT,
       "SET_VEL": MOT_CMD_SET_VEL, "SET_VEL_LIMIT": MOT_CMD_SET_VEL_LIMIT,
       "SET_ACC": MOT_CMD_SET_ACC, "SET_TERM_COND": MOT_CMD_SET_TERM_COND,
       "SET_OFFSET": MOT_CMD_SET_OFFSET, "SET_PROFILE": MOT_CMD_SET_PROFILE,
       "SET_DOUT": MOT_CMD_SET_DOUT, "SET_AOUT": MOT_CMD_SET_AOUT,
       "SET_FEED_HOLD_ENABLE": MOT_CMD_SET_FEED_HOLD_ENABLE,
       "SET_ADAPTIVE_FEED_ENABLE": MOT_CMD_SET_ADAPTIVE_FEED_ENABLE,
       "SET_LINEAR_UNITS": MOT_CMD_SET_LINEAR_UNITS,
       "SPINDLE_ON": MOT_CMD_SPINDLE_ON, "SPINDLE_OFF": MOT_CMD_SPINDLE_OFF,
       "SPINDLE_INCREASE": MOT_CMD_SPINDLE_INCREASE,
       "SPINDLE_DECREASE": MOT_CMD_SPINDLE_DECREASE,
       "SPINDLE_ORIENT": MOT_CMD_SPINDLE_ORIENT,
       "SPINDLE_BRAKE_ENGAGE": MOT_CMD_SPINDLE_BRAKE_ENGAGE,
       "SPINDLE_BRAKE_RELEASE": MOT_CMD_SPINDLE_BRAKE_RELEASE,
       "SPINDLE_SYNC_LINE": MOT_CMD_SPINDLE_SYNC_LINE,
       "RIGID_TAP": MOT_CMD_RIGID_TAP}
ECHO = {"NONE": MOT_ECHO_NONE, "DONE": MOT_ECHO_DONE,
        "ACCEPTED": MOT_ECHO_ACCEPTED, "REJECTED": MOT_ECHO_REJECTED}
MODE = {"FREE": MOT_MODE_FREE, "TELEOP": MOT_MODE_TELEOP,
        "COORD": MOT_MODE_COORD}
TERM = {"STOP": MOT_TERM_STOP, "EXACT": MOT_TERM_EXACT,
        "BLEND": MOT_TERM_BLEND}
MOTION_TYPE = {"NONE": MOT_MOTION_NONE, "TRAVERSE": MOT_MOTION_TRAVERSE,
               "FEED": MOT_MOTION_FEED, "ARC": MOT_MOTION_ARC,
               "TOOLCHANGE": MOT_MOTION_TOOLCHANGE,
               "PROBING": MOT_MOTION_PROBING,
               "INDEXROTARY": MOT_MOTION_INDEXROTARY}
KINS_TYPE = {"IDENTITY": MOT_KINS_IDENTITY,
             "FORWARD_ONLY": MOT_KINS_FORWARD_ONLY,
             "INVERSE_ONLY": MOT_KINS_INVERSE_ONLY, "BOTH": MOT_KINS_BOTH}
ORIENT_STATE = {"NONE": MOT_ORIENT_NONE, "RUNNING": MOT_ORIENT_RUNNING,
                "DONE": MOT_ORIENT_DONE, "FAULT": MOT_ORIENT_FAULT}
PROBE = {"NO_ERROR": MOT_PROBE_NO_ERROR, "AWAY": MOT_PROBE_AWAY}
HOME_FLAGS = {"IGNORE_LIMITS": HOME_IGNORE_LIMITS, "USE_INDEX": HOME_USE_INDEX,
              "IS_SHARED": HOME_IS_SHARED, "UNLOCK_FIRST": HOME_UNLOCK_FIRST,
              "ABSOLUTE_ENCODER": HOME_ABSOLUTE_ENCODER,
              "NO_REHOME": HOME_NO_REHOME, "NO_FINAL_MOVE": HOME_NO_FINAL_MOVE,
              "INDEX_NO_ENCODER_RESET": HOME_INDEX_NO_ENCODER_RESET}
JOINT_FLAGS = {"ACTIVE": MOT_JOINT_ACTIVE, "ENABLED": MOT_JOINT_ENABLED,
               "INPOS": MOT_JOINT_INPOS, "ERROR": MOT_JOINT_ERROR,
               "POS_SOFT": MOT_JOINT_POS_SOFT, "NEG_SOFT": MOT_JOINT_NEG_SOFT,
               "POS_HARD": MOT_JOINT_POS_HARD, "NEG_HARD": MOT_JOINT_NEG_HARD,
               "FERROR": MOT_JOINT_FERROR, "FAULT": MOT_JOINT_FAULT,
               "HOMING": MOT_JOINT_HOMING, "HOMED": MOT_JOINT_HOMED}
PROFILE = {"TRAPEZOID": FP_TRAPEZOID, "JERK": FP_JERK}
HOME_SEQ_NONE = HOME_SEQUENCE_NONE
CMD_LAST = MOT_CMD_LAST     # every command code is below this



# ------------------------------------------------------------ layout
# Where the compiler put the fields of the channel's structures (the
# headers' layout, offsetof): LAYOUT[struct] = (sizeof, fields), the
# fields in order as (name, offset, kind, count): kind "i32", "u32",
# "u64", "f64", "char" or another struct of LAYOUT, count > 1 for an
# array (the headers' sizes).  Padding and reserved fields are left out;
# a pose is listed by axis letters (x y z a b c u v w).  For tools and
# tests that look at the block with ctypes; the client uses the typed
# access above.

cdef tuple _f(str name, const volatile void *base, const volatile void *at,
              str kind, size_t count=1):
    return (name, <size_t>(<const volatile char *>at -
                           <const volatile char *>base), kind, count)


cdef tuple _layout_PmCartesian():
    cdef PmCartesian s
    cdef void *b = &s
    return sizeof(s), (
        _f("x", b, &s.x, "f64"),
        _f("y", b, &s.y, "f64"),
        _f("z", b, &s.z, "f64"),
    )


cdef tuple _layout_EmcPose():
    cdef EmcPose s
    cdef void *b = &s
    return sizeof(s), (
        _f("x", b, &s.tran.x, "f64"),
        _f("y", b, &s.tran.y, "f64"),
        _f("z", b, &s.tran.z, "f64"),
        _f("a", b, &s.a, "f64"),
        _f("b", b, &s.b, "f64"),
        _f("c", b, &s.c, "f64"),
        _f("u", b, &s.u, "f64"),
        _f("v", b, &s.v, "f64"),
        _f("w", b, &s.w, "f64"),
    )


cdef tuple _layout_command():
    cdef mot_command_t s
    cdef void *b = &s
    return sizeof(s), (
        _f("cmd", b, &s.cmd, "i32"),
        _f("joint", b, &s.joint, "i32"),
        _f("axis", b, &s.axis, "i32"),
        _f("ival", b, &s.ival, "i32"),
        _f("index", b, &s.index, "i32"),
        _f("id", b, &s.id, "i32"),
        _f("motion_type", b, &s.motion_type, "i32"),
        _f("turn", b, &s.turn, "i32"),
        _f("vel", b, &s.vel, "f64"),
        _f("ini_maxvel", b, &s.ini_maxvel, "f64"),
        _f("acc", b, &s.acc, "f64"),
        _f("jerk", b, &s.jerk, "f64"),
        _f("offset", b, &s.offset, "f64"),
        _f("value", b, &s.value, "f64"),
        _f("min_limit", b, &s.min_limit, "f64"),
        _f("max_limit", b, &s.max_limit, "f64"),
        _f("tolerance", b, &s.tolerance, "f64"),
        _f("comp", b, &s.comp, "f64", 3),
        _f("pos", b, &s.pos, "EmcPose"),
        _f("center", b, &s.center, "PmCartesian"),
        _f("normal", b, &s.normal, "PmCartesian"),
        _f("home_offset", b, &s.home_offset, "f64"),
        _f("home", b, &s.home, "f64"),
        _f("home_search_vel", b, &s.home_search_vel, "f64"),
        _f("home_latch_vel", b, &s.home_latch_vel, "f64"),
        _f("home_final_vel", b, &s.home_final_vel, "f64"),
        _f("home_sequence", b, &s.home_sequence, "i32"),
        _f("volatile_home", b, &s.volatile_home, "i32"),
        _f("home_flags", b, &s.home_flags, "u32"),
        _f("line", b, &s.line, "i32"),
        _f("epoch", b, &s.epoch, "u32"),
        _f("sync", b, &s.sync, "i32"),
        _f("pitch", b, &s.pitch, "f64"),
    )


cdef tuple _layout_spindle_status():
    cdef mot_spindle_status_t s
    cdef void *b = &s
    return sizeof(s), (
        _f("speed", b, &s.speed, "f64"),
        _f("speed_in", b, &s.speed_in, "f64"),
        _f("revs", b, &s.revs, "f64"),
        _f("orient_angle", b, &s.orient_angle, "f64"),
        _f("css_factor", b, &s.css_factor, "f64"),
        _f("on", b, &s.on, "i32"),
        _f("direction", b, &s.direction, "i32"),
        _f("brake", b, &s.brake, "i32"),
        _f("locked", b, &s.locked, "i32"),
        _f("orient_state", b, &s.orient_state, "i32"),
        _f("orient_fault", b, &s.orient_fault, "i32"),
        _f("at_speed", b, &s.at_speed, "i32"),
        _f("inhibit", b, &s.inhibit, "i32"),
        _f("amp_fault", b, &s.amp_fault, "i32"),
    )


cdef tuple _layout_joint_status():
    cdef mot_joint_status_t s
    cdef void *b = &s
    return sizeof(s), (
        _f("flags", b, &s.flags, "u32"),
        _f("home_state", b, &s.home_state, "i32"),
        _f("pos_cmd", b, &s.pos_cmd, "f64"),
        _f("pos_fb", b, &s.pos_fb, "f64"),
        _f("vel_cmd", b, &s.vel_cmd, "f64"),
        _f("acc_cmd", b, &s.acc_cmd, "f64"),
        _f("ferror", b, &s.ferror, "f64"),
        _f("ferror_limit", b, &s.ferror_limit, "f64"),
        _f("ferror_high_mark", b, &s.ferror_high_mark, "f64"),
        _f("motor_offset", b, &s.motor_offset, "f64"),
        _f("motor_pos_cmd", b, &s.motor_pos_cmd, "f64"),
        _f("motor_pos_fb", b, &s.motor_pos_fb, "f64"),
        _f("backlash_filt", b, &s.backlash_filt, "f64"),
        _f("min_pos_limit", b, &s.min_pos_limit, "f64"),
        _f("max_pos_limit", b, &s.max_pos_limit, "f64"),
        _f("vel_limit", b, &s.vel_limit, "f64"),
        _f("acc_limit", b, &s.acc_limit, "f64"),
        _f("jerk_limit", b, &s.jerk_limit, "f64"),
        _f("min_ferror", b, &s.min_ferror, "f64"),
        _f("max_ferror", b, &s.max_ferror, "f64"),
        _f("backlash", b, &s.backlash, "f64"),
        _f("free_target", b, &s.free_target, "f64"),
        _f("free_active", b, &s.free_active, "i32"),
        _f("jog_active", b, &s.jog_active, "i32"),
    )


cdef tuple _layout_axis_status():
    cdef mot_axis_status_t s
    cdef void *b = &s
    return sizeof(s), (
        _f("pos_cmd", b, &s.pos_cmd, "f64"),
        _f("vel_cmd", b, &s.vel_cmd, "f64"),
        _f("teleop_pos", b, &s.teleop_pos, "f64"),
        _f("teleop_vel", b, &s.teleop_vel, "f64"),
        _f("teleop_target", b, &s.teleop_target, "f64"),
        _f("min_pos_limit", b, &s.min_pos_limit, "f64"),
        _f("max_pos_limit", b, &s.max_pos_limit, "f64"),
        _f("vel_limit", b, &s.vel_limit, "f64"),
        _f("acc_limit", b, &s.acc_limit, "f64"),
        _f("jerk_limit", b, &s.jerk_limit, "f64"),
        _f("teleop_active", b, &s.teleop_active, "i32"),
        _f("jog_active", b, &s.jog_active, "i32"),
    )


cdef tuple _layout_status():
    cdef mot_status_t s
    cdef void *b = &s
    return sizeof(s), (
        _f("heartbeat", b, &s.heartbeat, "u64"),
        _f("mode", b, &s.mode, "i32"),
        _f("enabled", b, &s.enabled, "i32"),
        _f("in_position", b, &s.in_position, "i32"),
        _f("on_soft_limit", b, &s.on_soft_limit, "i32"),
        _f("override_limits", b, &s.override_limits, "i32"),
        _f("num_joints", b, &s.num_joints, "i32"),
        _f("num_joints_loaded", b, &s.num_joints_loaded, "i32"),
        _f("num_extrajoints", b, &s.num_extrajoints, "i32"),
        _f("kins_type", b, &s.kins_type, "i32"),
        _f("homing", b, &s.homing, "i32"),
        _f("all_homed", b, &s.all_homed, "i32"),
        _f("paused", b, &s.paused, "i32"),
        _f("probing", b, &s.probing, "i32"),
        _f("probe_tripped", b, &s.probe_tripped, "i32"),
        _f("queue_depth", b, &s.queue_depth, "i32"),
        _f("motion_id", b, &s.motion_id, "i32"),
        _f("motion_type", b, &s.motion_type, "i32"),
        _f("profile", b, &s.profile, "i32"),
        _f("coord_error", b, &s.coord_error, "i32"),
        _f("error", b, &s.error, "i32"),
        _f("num_dio", b, &s.num_dio, "i32"),
        _f("num_aio", b, &s.num_aio, "i32"),
        _f("num_spindles", b, &s.num_spindles, "i32"),
        _f("term_cond", b, &s.term_cond, "i32"),
        _f("feed_scale", b, &s.feed_scale, "f64"),
        _f("rapid_scale", b, &s.rapid_scale, "f64"),
        _f("current_vel", b, &s.current_vel, "f64"),
        _f("distance_to_go", b, &s.distance_to_go, "f64"),
        _f("requested_vel", b, &s.requested_vel, "f64"),
        _f("vel_limit", b, &s.vel_limit, "f64"),
        _f("acc_limit", b, &s.acc_limit, "f64"),
        _f("tolerance", b, &s.tolerance, "f64"),
        _f("servo_period", b, &s.servo_period, "f64"),
        _f("traj_period", b, &s.traj_period, "f64"),
        _f("carte_pos_cmd", b, &s.carte_pos_cmd, "EmcPose"),
        _f("carte_pos_fb", b, &s.carte_pos_fb, "EmcPose"),
        _f("carte_pos_fb_ok", b, &s.carte_pos_fb_ok, "i32"),
        _f("probed_pos", b, &s.probed_pos, "EmcPose"),
        _f("tool_offset", b, &s.tool_offset, "EmcPose"),
        _f("dout", b, &s.dout, "u64"),
        _f("din", b, &s.din, "u64"),
        _f("joint", b, &s.joint, "mot_joint_status_t", MOT_MAX_JOINTS),
        _f("axis", b, &s.axis, "mot_axis_status_t", MOT_MAX_AXES),
        _f("program_line", b, &s.program_line, "i32"),
        _f("feed_hold_enabled", b, &s.feed_hold_enabled, "i32"),
        _f("adaptive_enabled", b, &s.adaptive_enabled, "i32"),
        _f("feed_hold", b, &s.feed_hold, "i32"),
        _f("feed_inhibit", b, &s.feed_inhibit, "i32"),
        _f("queue_taken", b, &s.queue_taken, "i32"),
        _f("queue_err_count", b, &s.queue_err_count, "u32"),
        _f("adaptive_feed", b, &s.adaptive_feed, "f64"),
        _f("feed_upm", b, &s.feed_upm, "f64"),
        _f("linear_units", b, &s.linear_units, "f64"),
        _f("ain", b, &s.ain, "f64", MOT_MAX_AIO),
        _f("aout", b, &s.aout, "f64", MOT_MAX_AIO),
        _f("spindle", b, &s.spindle, "mot_spindle_status_t", MOT_MAX_SPINDLES),
        _f("spindle_wait", b, &s.spindle_wait, "i32"),
        _f("queue_held", b, &s.queue_held, "i32"),
    )


cdef tuple _layout_msg():
    cdef mot_msg_t s
    cdef void *b = &s
    return sizeof(s), (
        _f("n", b, &s.n, "u64"),
        _f("text", b, &s.text, "char", MOT_MSG_LEN),
    )


cdef tuple _layout_channel():
    # (the block holds the move queue: too large for the stack)
    cdef mot_channel_t *s = <mot_channel_t *>calloc(1, sizeof(s[0]))
    cdef void *b = s
    if s == NULL:
        raise MemoryError()
    try:
        return sizeof(s[0]), (
            _f("magic", b, &s.magic, "u32"),
            _f("version", b, &s.version, "u32"),
            _f("size", b, &s.size, "u32"),
            _f("lock_pid", b, &s.lock_pid, "i32"),
            _f("cmd_seq", b, &s.cmd_seq, "u32"),
            _f("echo_seq", b, &s.echo_seq, "u32"),
            _f("echo_status", b, &s.echo_status, "i32"),
            _f("echo_cmd", b, &s.echo_cmd, "i32"),
            _f("echo_reason", b, &s.echo_reason, "char", MOT_REASON_LEN),
            _f("command", b, &s.command, "mot_command_t"),
            _f("status_seq", b, &s.status_seq, "u32"),
            _f("status", b, &s.status, "mot_status_t"),
            _f("msg_count", b, &s.msg_count, "u64"),
            _f("msgs", b, &s.msgs, "mot_msg_t", MOT_MSG_RING),
            _f("q_head", b, &s.q_head, "u32"),
            _f("q_tail", b, &s.q_tail, "u32"),
            _f("q_err_count", b, &s.q_err_count, "u32"),
            _f("q_err_cmd", b, &s.q_err_cmd, "i32"),
            _f("q_err_id", b, &s.q_err_id, "i32"),
            _f("q_err_line", b, &s.q_err_line, "i32"),
            _f("q_err_reason", b, &s.q_err_reason, "char", MOT_REASON_LEN),
            _f("queue", b, &s.queue, "mot_command_t", MOT_QUEUE_SIZE),
        )
    finally:
        free(s)


LAYOUT = {"PmCartesian": _layout_PmCartesian(),
          "EmcPose": _layout_EmcPose(),
          "mot_command_t": _layout_command(),
          "mot_spindle_status_t": _layout_spindle_status(),
          "mot_joint_status_t": _layout_joint_status(),
          "mot_axis_status_t": _layout_axis_status(),
          "mot_status_t": _layout_status(),
          "mot_msg_t": _layout_msg(),
          "mot_channel_t": _layout_channel()}

class ChannelError(Exception):
    """The block is missing, gone, or not a channel of this version."""


cdef const halsdk_api *_api = NULL


cdef const halsdk_api *get_api() except NULL:
    """The core's C API table, taken as every compiled component takes it
    (import_halsdk() of halsdk_api.h)."""
    global _api
    if _api == NULL:
        import_halsdk()
        _api = halsdk_api_ptr
        if _api.version < 4:
            _api = NULL
            raise ChannelError("the halsdk core is too old for the motion "
                               "channel (C API version 4 needed)")
    return _api


cdef tuple _pose(EmcPose *p):
    return (p.tran.x, p.tran.y, p.tran.z, p.a, p.b, p.c, p.u, p.v, p.w)


cdef void _set_pose(EmcPose *p, object v) except *:
    if len(v) != MOT_MAX_AXES:
        raise ValueError("a pose needs 9 values (X Y Z A B C U V W)")
    p.tran.x, p.tran.y, p.tran.z = v[0], v[1], v[2]
    p.a, p.b, p.c, p.u, p.v, p.w = v[3], v[4], v[5], v[6], v[7], v[8]


cdef void _set_cart(PmCartesian *p, object v) except *:
    if len(v) != 3:
        raise ValueError("a vector needs 3 values (X Y Z)")
    p.x, p.y, p.z = v[0], v[1], v[2]


_INT_FIELDS = ("joint", "axis", "ival", "index", "id", "motion_type",
               "turn", "home_sequence", "volatile_home", "line", "sync")
_FLOAT_FIELDS = ("vel", "ini_maxvel", "acc", "jerk", "offset", "value",
                 "min_limit", "max_limit", "tolerance", "home_offset",
                 "home", "home_search_vel", "home_latch_vel",
                 "home_final_vel", "pitch")
_KNOWN = set(_INT_FIELDS + _FLOAT_FIELDS +
             ("home_flags", "comp", "pos", "center", "normal"))

SIZE = sizeof(mot_channel_t)
MAGIC = MOT_CHANNEL_MAGIC
VERSION = MOT_CHANNEL_VERSION
MAX_JOINTS = MOT_MAX_JOINTS
MAX_AXES = MOT_MAX_AXES
MAX_SPINDLES = MOT_MAX_SPINDLES
MAX_AIO = MOT_MAX_AIO
REASON_LEN = MOT_REASON_LEN
MSG_LEN = MOT_MSG_LEN
MSG_RING = MOT_MSG_RING
QUEUE_SIZE = MOT_QUEUE_SIZE


cdef void _fill(mot_command_t *rec, int cmd, dict args) except *:
    unknown = set(args) - _KNOWN
    if unknown:
        raise TypeError(f"unknown command field(s) {sorted(unknown)}")
    memset(rec, 0, sizeof(mot_command_t))
    rec.cmd = cmd
    rec.joint = -1
    rec.axis = -1
    for k in _INT_FIELDS:
        if k in args:
            setattr_int(rec, k, args[k])
    for k in _FLOAT_FIELDS:
        if k in args:
            setattr_float(rec, k, args[k])
    if "home_flags" in args:
        rec.home_flags = args["home_flags"]
    if "comp" in args:
        v = args["comp"]
        if len(v) != 3:
            raise ValueError("comp needs 3 values")
        rec.comp[0], rec.comp[1], rec.comp[2] = v[0], v[1], v[2]
    if "pos" in args:
        _set_pose(&rec.pos, args["pos"])
    if "center" in args:
        _set_cart(&rec.center, args["center"])
    if "normal" in args:
        _set_cart(&rec.normal, args["normal"])


cdef class Channel:
    """The channel block named ``name`` in the attached HAL instance."""

    cdef mot_channel_t *ch
    cdef long long handle
    cdef readonly str name
    cdef readonly int pid

    def __init__(self, str name, int pid):
        cdef const halsdk_api *api = get_api()
        hal = Hal.current()
        if hal is None:
            raise InstanceError(f"motion channel '{name}': this process is "
                                "not attached to a HAL instance")
        addr, size = hal.shared_block(name)     # NotFoundError if none
        cdef bytes b = name.encode()
        self.handle = api.shmem_attach(b)
        if self.handle < 0:
            raise ChannelError(f"shared block '{name}' vanished")
        self.ch = <mot_channel_t *>api.shmem_ptr(self.handle)
        self.name = name
        self.pid = pid
        if self.ch == NULL or <uintptr_t>self.ch != <uintptr_t>addr:
            raise ChannelError(f"shared block '{name}' vanished")
        if size < sizeof(mot_channel_t):
            raise ChannelError(
                f"shared block '{name}' has {size} bytes, a motion channel "
                f"needs {sizeof(mot_channel_t)}")
        if self.ch.magic != MOT_CHANNEL_MAGIC:
            raise ChannelError(f"shared block '{name}' is not a motion "
                               f"channel (magic {self.ch.magic:#x})")
        if self.ch.version != MOT_CHANNEL_VERSION:
            raise ChannelError(
                f"motion channel '{name}' has version {self.ch.version}, "
                f"this client speaks version {MOT_CHANNEL_VERSION}")
        if self.ch.size < sizeof(mot_channel_t):
            raise ChannelError(
                f"motion channel '{name}' declares {self.ch.size} bytes, "
                f"this client needs {sizeof(mot_channel_t)}")

    cdef mot_channel_t *live(self) except NULL:
        """The block, or ChannelError when its owner went away."""
        if self.ch == NULL or _api.shmem_ptr(self.handle) != <void *>self.ch:
            self.ch = NULL
            raise ChannelError(f"motion channel '{self.name}' is gone "
                               "(motmod was unloaded)")
        return self.ch

    def alive(self) -> bool:
        return (self.ch != NULL and
                _api.shmem_ptr(self.handle) == <void *>self.ch)

    # ---------------------------------------------------------- lock

    def try_lock(self) -> int:
        """Take the client lock; returns 0, or the pid of the live
        process that holds it."""
        cdef mot_channel_t *c = self.live()
        cdef int32_t owner
        while True:
            if mch_cas_i32(&c.lock_pid, 0, self.pid):
                return 0
            owner = mch_load_i32(&c.lock_pid)
            if owner == 0:
                continue
            # our own pid: a lock this process left (the Python side
            # serializes its own senders)
            if owner == self.pid or mch_pid_dead(owner):
                if mch_cas_i32(&c.lock_pid, owner, self.pid):
                    return 0
                continue
            return owner

    def unlock(self):
        cdef mot_channel_t *c = self.live()
        mch_cas_i32(&c.lock_pid, self.pid, 0)

    # ---------------------------------------------------------- commands

    def idle(self) -> bool:
        """The handler has taken the last command (echo_seq == cmd_seq)."""
        cdef mot_channel_t *c = self.live()
        return mch_load32(&c.echo_seq) == mch_load32(&c.cmd_seq)

    def send(self, int cmd, dict args) -> int:
        """Write a command record and publish it; returns its sequence
        number.  The caller holds the lock and has seen idle()."""
        cdef mot_channel_t *c = self.live()
        cdef mot_command_t rec
        cdef uint32_t seq
        _fill(&rec, cmd, args)
        memcpy(&c.command, &rec, sizeof(rec))
        seq = mch_load32(&c.cmd_seq) + 1
        if seq == 0:
            seq = 1
        mch_release()
        mch_store32(&c.cmd_seq, seq)
        return seq

    def echo(self) -> tuple:
        """(echo_seq, echo_status, echo_cmd, reason) as last published."""
        cdef mot_channel_t *c = self.live()
        cdef uint32_t seq = mch_load32(&c.echo_seq)
        cdef int32_t st = c.echo_status
        cdef int32_t code = c.echo_cmd
        cdef char reason[MOT_REASON_LEN]
        memcpy(reason, c.echo_reason, MOT_REASON_LEN)
        reason[MOT_REASON_LEN - 1] = 0
        return seq, st, code, reason.decode("utf-8", "replace")

    # ---------------------------------------------------------- queue

    def queue_state(self) -> tuple:
        """(q_head, q_tail, q_err_count) of the move queue ring."""
        cdef mot_channel_t *c = self.live()
        cdef uint32_t err = mch_load32(&c.q_err_count)
        cdef uint32_t tail = mch_load32(&c.q_tail)
        return mch_load32(&c.q_head), tail, err

    def queue_free(self) -> int:
        """Places free in the move queue ring."""
        cdef mot_channel_t *c = self.live()
        cdef uint32_t used = mch_load32(&c.q_head) - mch_load32(&c.q_tail)
        return MOT_QUEUE_SIZE - <int>used

    def push(self, int cmd, dict args, uint32_t epoch) -> int:
        """Write one record into the move queue ring.  Returns 0 when it
        was written, 1 when the ring is full, or the pid of the live
        process that holds the client lock (nothing written)."""
        cdef mot_channel_t *c = self.live()
        cdef mot_command_t rec
        cdef uint32_t head, tail
        _fill(&rec, cmd, args)
        rec.epoch = epoch
        owner = self.try_lock()
        if owner:
            return owner
        try:
            head = c.q_head
            tail = mch_load32(&c.q_tail)
            if head - tail >= <uint32_t>MOT_QUEUE_SIZE:
                return 1
            memcpy(&c.queue[head % MOT_QUEUE_SIZE], &rec, sizeof(rec))
            mch_store32(&c.q_head, head + 1)
            return 0
        finally:
            self.unlock()

    def queue_error(self) -> tuple:
        """(q_err_count, cmd, id, line, reason) of the last rejected
        queued record."""
        cdef mot_channel_t *c = self.live()
        cdef uint32_t n = mch_load32(&c.q_err_count)
        cdef char reason[MOT_REASON_LEN]
        memcpy(reason, c.q_err_reason, MOT_REASON_LEN)
        reason[MOT_REASON_LEN - 1] = 0
        return (n, c.q_err_cmd, c.q_err_id, c.q_err_line,
                reason.decode("utf-8", "replace"))

    # ---------------------------------------------------------- status

    def status(self, double timeout=2.0) -> dict:
        """One consistent snapshot of the status, as a dict of plain
        values (joints and axes as lists of dicts)."""
        cdef mot_channel_t *c = self.live()
        cdef mot_status_t st
        cdef uint32_t s1, s2
        cdef long k = 0
        cdef double end = 0
        cdef bint ok = False
        with nogil:
            while True:
                s1 = mch_load32(&c.status_seq)
                if not (s1 & 1):
                    memcpy(&st, <void *>&c.status, sizeof(st))
                    mch_acquire()
                    s2 = mch_load32(&c.status_seq)
                    if s1 == s2:
                        ok = True
                        break
                # the writer is in the middle of an update: spin a little,
                # then let it run (it may share our CPU)
                k += 1
                if k > 100:
                    if end == 0:
                        end = mch_now() + timeout
                    elif mch_now() > end:
                        break
                    sched_yield()
        if not ok:
            raise ChannelError("no consistent status snapshot within "
                               f"{timeout:g} s (the writer never finishes "
                               "an update)")
        return _status_dict(&st)

    # ---------------------------------------------------------- messages

    def msg_count(self) -> int:
        cdef mot_channel_t *c = self.live()
        return mch_load64(&c.msg_count)

    def messages(self, uint64_t r) -> tuple:
        """Messages from number r on: (list of texts, next r, lost)."""
        cdef mot_channel_t *c = self.live()
        cdef uint64_t count = mch_load64(&c.msg_count)
        cdef mot_msg_t m
        cdef uint64_t lost = 0
        out = []
        while r < count:
            if count - r >= MOT_MSG_RING:
                lost += count - MOT_MSG_RING + 1 - r
                r = count - MOT_MSG_RING + 1
            memcpy(&m, <void *>&c.msgs[r % MOT_MSG_RING], sizeof(m))
            mch_acquire()
            count = mch_load64(&c.msg_count)
            if count - r >= MOT_MSG_RING:
                continue        # overwritten while copying: skip ahead
            if m.n != r:        # not the message expected: drop it
                lost += 1
                r += 1
                continue
            m.text[MOT_MSG_LEN - 1] = 0
            out.append(m.text.decode("utf-8", "replace"))
            r += 1
        return out, r, lost


cdef void setattr_int(mot_command_t *r, str k, object v) except *:
    cdef int32_t x = v
    if k == "joint":
        r.joint = x
    elif k == "axis":
        r.axis = x
    elif k == "ival":
        r.ival = x
    elif k == "index":
        r.index = x
    elif k == "id":
        r.id = x
    elif k == "motion_type":
        r.motion_type = x
    elif k == "turn":
        r.turn = x
    elif k == "home_sequence":
        r.home_sequence = x
    elif k == "volatile_home":
        r.volatile_home = x
    elif k == "line":
        r.line = x
    elif k == "sync":
        r.sync = x


cdef void setattr_float(mot_command_t *r, str k, object v) except *:
    cdef double x = v
    if k == "vel":
        r.vel = x
    elif k == "ini_maxvel":
        r.ini_maxvel = x
    elif k == "acc":
        r.acc = x
    elif k == "jerk":
        r.jerk = x
    elif k == "offset":
        r.offset = x
    elif k == "value":
        r.value = x
    elif k == "min_limit":
        r.min_limit = x
    elif k == "max_limit":
        r.max_limit = x
    elif k == "tolerance":
        r.tolerance = x
    elif k == "home_offset":
        r.home_offset = x
    elif k == "home":
        r.home = x
    elif k == "home_search_vel":
        r.home_search_vel = x
    elif k == "home_latch_vel":
        r.home_latch_vel = x
    elif k == "home_final_vel":
        r.home_final_vel = x
    elif k == "pitch":
        r.pitch = x


cdef dict _joint_dict(mot_joint_status_t *j):
    return dict(
        flags=j.flags, home_state=j.home_state, pos_cmd=j.pos_cmd,
        pos_fb=j.pos_fb, vel_cmd=j.vel_cmd, acc_cmd=j.acc_cmd,
        ferror=j.ferror, ferror_limit=j.ferror_limit,
        ferror_high_mark=j.ferror_high_mark, motor_offset=j.motor_offset,
        motor_pos_cmd=j.motor_pos_cmd, motor_pos_fb=j.motor_pos_fb,
        backlash_filt=j.backlash_filt, min_pos_limit=j.min_pos_limit,
        max_pos_limit=j.max_pos_limit, vel_limit=j.vel_limit,
        acc_limit=j.acc_limit, jerk_limit=j.jerk_limit,
        min_ferror=j.min_ferror, max_ferror=j.max_ferror,
        backlash=j.backlash, free_target=j.free_target,
        free_active=j.free_active != 0, jog_active=j.jog_active != 0)


cdef dict _axis_dict(mot_axis_status_t *a):
    return dict(
        pos_cmd=a.pos_cmd, vel_cmd=a.vel_cmd, teleop_pos=a.teleop_pos,
        teleop_vel=a.teleop_vel, teleop_target=a.teleop_target,
        min_pos_limit=a.min_pos_limit, max_pos_limit=a.max_pos_limit,
        vel_limit=a.vel_limit, acc_limit=a.acc_limit,
        jerk_limit=a.jerk_limit, teleop_active=a.teleop_active != 0,
        jog_active=a.jog_active != 0)


cdef dict _spindle_dict(mot_spindle_status_t *p):
    return dict(
        speed=p.speed, speed_in=p.speed_in, revs=p.revs,
        orient_angle=p.orient_angle, css_factor=p.css_factor,
        on=p.on != 0, direction=p.direction, brake=p.brake != 0,
        locked=p.locked != 0, orient_state=p.orient_state,
        orient_fault=p.orient_fault, at_speed=p.at_speed != 0,
        inhibit=p.inhibit != 0, amp_fault=p.amp_fault != 0)


cdef dict _status_dict(mot_status_t *s):
    cdef int n = s.num_joints_loaded
    cdef int i
    if n < 0:
        n = 0
    if n > MOT_MAX_JOINTS:
        n = MOT_MAX_JOINTS
    return dict(
        heartbeat=s.heartbeat, mode=s.mode, enabled=s.enabled != 0,
        in_position=s.in_position != 0, on_soft_limit=s.on_soft_limit != 0,
        override_limits=s.override_limits != 0, num_joints=s.num_joints,
        num_joints_loaded=s.num_joints_loaded,
        num_extrajoints=s.num_extrajoints, kins_type=s.kins_type,
        homing=s.homing != 0, all_homed=s.all_homed != 0,
        paused=s.paused != 0, probing=s.probing != 0,
        probe_tripped=s.probe_tripped != 0, queue_depth=s.queue_depth,
        motion_id=s.motion_id, motion_type=s.motion_type,
        profile=s.profile, coord_error=s.coord_error != 0,
        error=s.error != 0, num_dio=s.num_dio, num_aio=s.num_aio,
        num_spindles=s.num_spindles, term_cond=s.term_cond,
        feed_scale=s.feed_scale, rapid_scale=s.rapid_scale,
        current_vel=s.current_vel, distance_to_go=s.distance_to_go,
        requested_vel=s.requested_vel, vel_limit=s.vel_limit,
        acc_limit=s.acc_limit, tolerance=s.tolerance,
        servo_period=s.servo_period, traj_period=s.traj_period,
        carte_pos_cmd=_pose(&s.carte_pos_cmd),
        carte_pos_fb=_pose(&s.carte_pos_fb),
        carte_pos_fb_ok=s.carte_pos_fb_ok != 0,
        probed_pos=_pose(&s.probed_pos), tool_offset=_pose(&s.tool_offset),
        dout=s.dout, din=s.din,
        program_line=s.program_line,
        feed_hold_enabled=s.feed_hold_enabled != 0,
        adaptive_enabled=s.adaptive_enabled != 0,
        feed_hold=s.feed_hold != 0, feed_inhibit=s.feed_inhibit != 0,
        queue_taken=<uint32_t>s.queue_taken,
        queue_err_count=s.queue_err_count,
        adaptive_feed=s.adaptive_feed, feed_upm=s.feed_upm,
        linear_units=s.linear_units, spindle_wait=s.spindle_wait,
        queue_held=s.queue_held != 0,
        ain=[s.ain[i] for i in range(min(max(s.num_aio, 0), MOT_MAX_AIO))],
        aout=[s.aout[i] for i in range(min(max(s.num_aio, 0), MOT_MAX_AIO))],
        spindles=[_spindle_dict(&s.spindle[i]) for i in
                  range(min(max(s.num_spindles, 0), MOT_MAX_SPINDLES))],
        joints=[_joint_dict(&s.joint[i]) for i in range(n)],
        axes=[_axis_dict(&s.axis[i]) for i in range(MOT_MAX_AXES)])
