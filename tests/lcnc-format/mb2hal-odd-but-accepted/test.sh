#!/bin/bash
# the Modbus simulator on a free loopback port; x.ini from x.ini.in
. ../lib/modbus-simulator.sh
cat > test.hal <<'HAL'
loadusr -W mb2hal config=x.ini
loadusr -w sleep 0.5
getp mb2hal.in.level.int
getp mb2hal.in.pressure.int
show pin mb2hal
unloadusr mb2hal
HAL
halrun -f test.hal > out 2>&1
echo "halrun: $?"
grep -v '^Note:' out
# NELEMENTS=2 wins over the three names; TRANSACTION_02 is not read
grep '^fc=' log | sort -u
rm -f test.hal
