# build the hand-written module with halcompile, load it from a HAL file
export HALSDK_PATH=$PWD
halcompile --compile capiplc.c > /dev/null 2>&1 || echo "halcompile failed"
halrun -f plc.hal
echo "halrun: $?"
