#!/usr/bin/env python3
"""Read the error channel as the manual shows: the error of a command the
task refuses (MDI in E-stop), then the operator's text, display and error
messages, each with its kind."""
import sys
import time

import linuxcnc

c = linuxcnc.command()
e = linuxcnc.error_channel()


def next_message(timeout=10.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        error = e.poll()
        if error:
            return error
        time.sleep(0.01)
    sys.exit(f"no message within {timeout:g} s")


def describe(error):
    kind, text = error
    if kind in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
        typus = "error"
    else:
        typus = "info"
    return typus


for _ in range(1000):                   # what earlier clients left
    if e.poll() is None:
        break
print("channel empty:", e.poll() is None)

c.state(linuxcnc.STATE_ESTOP)
c.wait_complete()
c.mdi("G0 X1")
print("refused:", c.wait_complete() == linuxcnc.RCS_ERROR)
error = next_message()
print("refusal is an", describe(error), "of kind", error[0])
print("it says why:", len(error[1]) > 0)

c.text_msg("hello text")
c.display_msg("hello display")
c.error_msg("hello error")
print("sent:", c.wait_complete() == linuxcnc.RCS_DONE)
for _ in range(3):
    error = next_message()
    print(describe(error), error)
print("nothing more:", e.poll() is None)

c.text_msg("x" * 300)                   # at most 254 characters are kept
c.wait_complete()
kind, text = next_message()
print("long text kept:", len(text))

# expect: channel empty: True
# expect: refused: True
# expect: refusal is an error of kind 11
# expect: it says why: True
# expect: sent: True
# expect: info (12, 'hello text')
# expect: info (13, 'hello display')
# expect: error (11, 'hello error')
# expect: nothing more: True
# expect: long text kept: 254
