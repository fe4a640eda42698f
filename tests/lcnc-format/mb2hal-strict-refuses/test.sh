#!/bin/bash
# the Modbus simulator on a free loopback port; x.ini from x.ini.in
. ../lib/modbus-simulator.sh
# the same file that runs with a warning is refused with --strict
cat > test.hal <<'HAL'
loadusr -W mb2hal --strict config=x.ini
HAL
halrun -f test.hal > out 2>&1
[ $? -ne 0 ] && echo "halrun failed"
grep '^mb2hal' out
grep -c Traceback out
mb2hal --help | grep -c -- '--strict'
mb2hal --strict config=x.ini 2>&1
echo "mb2hal: $?"
sort -u log
rm -f test.hal
