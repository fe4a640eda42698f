#!/bin/bash
# the Modbus simulator on a free loopback port; x.ini from x.ini.in
. ../lib/modbus-simulator.sh
cat > test.hal <<'HAL'
loadusr -W mb2hal config=x.ini
setp mb2hal.pair.00.int 11
setp mb2hal.pair.01.int 22
setp mb2hal.single.00.int 33
loadusr -w sleep 0.6
getp mb2hal.single.num_errors
getp mb2hal.back.00.int
show pin mb2hal.pair
unloadusr mb2hal
HAL
halrun -f test.hal > out 2>&1
echo "halrun: $?"
grep '^mb2hal: warning' out
grep -c 'transaction pair: not sent' out
awk '$NF ~ /mb2hal.pair.num_errors/ { print ($4 != "0x00000000") ? "pair errors counted" : "pair no errors" }' out
grep -v '^mb2hal' out | grep -v num_errors | grep -v '^Note:'
# what reached the device: no fc=6 at 20 or 21; last value at each address
awk '{ last[$1 " " $2] = $0 } END { for (k in last) print last[k] }' log | sort
rm -f test.hal
