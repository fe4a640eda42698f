# Sourced by the mb2hal-* tests (bash): start the example Modbus simulator
# of the checkout on a free loopback port, its requests logged to ./log,
# and write x.ini from x.ini.in with @PORT@ filled in.  The simulator and
# the files are removed when the test exits.
export HALSDK_INSTANCE=${HALSDK_INSTANCE:-lcnc}-mb$$
rm -f port log x.ini out
${PYTHON:-python3} ../../../examples/modbus/simulator.py --port 0 \
    --port-file port --log log > /dev/null 2>&1 &
SIM=$!
trap 'kill $SIM 2>/dev/null; wait $SIM 2>/dev/null; rm -f port log x.ini out' EXIT
for i in $(seq 100); do [ -s port ] && break; sleep 0.1; done
sed "s/@PORT@/$(cat port)/" x.ini.in > x.ini
