# a module whose rtapi_app_main fails: a clear error, no crash
export HALSDK_PATH=$PWD
halcompile --compile capifail.c > /dev/null 2>&1 || echo "halcompile failed"
halrun -f fail.hal
echo "halrun: $?"
halrun -k -f keepgoing.hal
echo "halrun -k: $?"
