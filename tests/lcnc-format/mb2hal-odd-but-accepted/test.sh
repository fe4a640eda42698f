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
