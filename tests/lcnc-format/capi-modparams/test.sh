# module parameters of every RTAPI_MP_* kind
export HALSDK_PATH=$PWD
halcompile --compile capimp.c > /dev/null 2>&1 || echo "halcompile failed"
halrun -f modparams.hal
echo "halrun: $?"
halrun -f defaults.hal
echo "halrun: $?"
