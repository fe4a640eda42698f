#!/usr/bin/env python3
"""Digital and analog outputs, the optional stop and block delete flags,
the debug level, the interpreter reset and the parameter file sync: each
command, then the status that shows it."""
import sys

import linuxcnc

s = linuxcnc.stat()
c = linuxcnc.command()


def done(what, timeout=5.0):
    if c.wait_complete(timeout) != linuxcnc.RCS_DONE:
        sys.exit(what + " failed")
    s.poll()


try:
    c.state(linuxcnc.STATE_ESTOP_RESET)
    done("E-stop reset")
    c.state(linuxcnc.STATE_ON)
    done("machine on")

    c.set_digital_output(1, 1)
    done("digital output")
    print("dout:", s.dout[:4])
    c.set_analog_output(2, 2.5)
    done("analog output")
    print("aout:", s.aout[:4])
    c.set_digital_output(1, 0)
    c.set_analog_output(2, 0.0)
    done("outputs off")
    print("outputs off:", s.dout[:4], s.aout[:4])

    c.set_optional_stop(0)
    done("optional stop")
    print("optional stop:", s.optional_stop)
    c.set_optional_stop(1)
    done("optional stop")
    print("optional stop:", s.optional_stop)
    c.set_block_delete(1)
    done("block delete")
    print("block delete:", s.block_delete)
    c.set_block_delete(0)
    done("block delete")
    print("block delete:", s.block_delete)

    c.debug(linuxcnc.DEBUG_CONFIG)
    done("debug")
    print("debug:", s.debug)
    c.debug(0)
    done("debug")

    c.mode(linuxcnc.MODE_MDI)
    done("mdi mode")
    c.reset_interpreter()
    print("interpreter reset:", c.wait_complete() == linuxcnc.RCS_DONE)
    c.task_plan_synch()
    print("parameters synced:", c.wait_complete() == linuxcnc.RCS_DONE)
    print("serials counted:", c.serial)
finally:
    c.state(linuxcnc.STATE_ESTOP)
    c.wait_complete()

# expect: dout: (0, 1, 0, 0)
# expect: aout: (0.0, 0.0, 2.5, 0.0)
# expect: outputs off: (0, 0, 0, 0) (0.0, 0.0, 0.0, 0.0)
# expect: optional stop: False
# expect: optional stop: True
# expect: block delete: True
# expect: block delete: False
# expect: debug: 2
# expect: interpreter reset: True
# expect: parameters synced: True
# expect: serials counted: 15
