#!/usr/bin/env python3
# the module functions of LinuxCNC's hal module: new_sig, connect,
# set_p, get_value, pin_has_writer, component_exists
import hal

c = hal.component("pysig")
c.newpin("x", hal.HAL_FLOAT, hal.HAL_OUT)
c.newpin("y", hal.HAL_FLOAT, hal.HAL_IN)
c.newpin("n", hal.HAL_S32, hal.HAL_IN)
c.ready()
hal.new_sig("xy", hal.HAL_FLOAT)
hal.connect("pysig.x", "xy")
hal.connect("pysig.y", "xy")
c["x"] = 4.5
print("xy", hal.get_value("xy"))
print("y", hal.get_value("pysig.y"))
hal.set_p("pysig.n", "-12")
print("n", hal.get_value("pysig.n"))
print("n pin", c["n"])
hal.set_p("lowpass.0.gain", "0.125")
print("gain", hal.get_value("lowpass.0.gain"))
print("writer x", hal.pin_has_writer("pysig.x"))
print("writer n", hal.pin_has_writer("pysig.n"))
print("exists", hal.component_exists("pysig"), hal.component_exists("nope"))
print("is ready", hal.component_is_ready("pysig"))
