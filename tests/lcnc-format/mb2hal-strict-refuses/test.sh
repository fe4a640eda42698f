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
