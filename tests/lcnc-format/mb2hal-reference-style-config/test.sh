#!/bin/bash
# the Modbus simulator on a free loopback port; x.ini from x.ini.in
. ../lib/modbus-simulator.sh
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
loadusr -w ./mark
unloadusr mb2hal
HAL
# the writes before unloadusr: halsdk's mb2hal then writes its coils OFF
# (its safe state), which LinuxCNC's does not
printf '#!/bin/sh\necho end-of-run >> log\n' > mark
chmod +x mark
halrun -f test.hal > out 2>&1
echo "halrun: $?"
grep -v '^Note:' out
# the last value written at each address
sed '/^end-of-run$/q' log | grep '^fc=[56]\|^fc=1[56] ' | awk '{ last[$1 " " $2] = $0 } END { for (k in last) print last[k] }' | sort
grep '^fc=[1234] ' log | cut -d' ' -f1 | sort -u
rm -f test.hal mark
