#!/bin/bash
# start the Modbus simulator on a free loopback port; fill @PORT@ in x.ini
export HALSDK_INSTANCE=${HALSDK_INSTANCE:-lcnc}-mb$$
rm -f port log x.ini out
${PYTHON:-python3} ../../../examples/modbus/simulator.py --port 0 \
    --port-file port --log log > /dev/null 2>&1 &
SIM=$!
trap 'kill $SIM 2>/dev/null; wait $SIM 2>/dev/null; rm -f port log x.ini out' EXIT
for i in $(seq 100); do [ -s port ] && break; sleep 0.1; done
sed "s/@PORT@/$(cat port)/" x.ini.in > x.ini
cat > test.hal <<'HAL'
loadusr -W mb2hal --strict config=x.ini
setp mb2hal.enable.00.bit 1
setp mb2hal.lamps.01.bit 1
setp mb2hal.setpoint.00.float 1234
setp mb2hal.limits.00.int 7
setp mb2hal.limits.01.int 70000
loadusr -w sleep 0.8
getp mb2hal.sensors.level.int
getp mb2hal.sensors.speed.float
getp mb2hal.inputs.00.bit
getp mb2hal.inputs.01.bit-inv
getp mb2hal.lampsBack.01.bit
getp mb2hal.07.00.int
unloadusr mb2hal
HAL
halrun -f test.hal > out 2>&1
echo "halrun: $?"
grep -v '^Note:' out
# the last value written at each address
grep -v '^fc=[1234] ' log | awk '{ last[$1 " " $2] = $0 } END { for (k in last) print last[k] }' | sort
grep '^fc=[1234] ' log | cut -d' ' -f1 | sort -u
rm -f test.hal
