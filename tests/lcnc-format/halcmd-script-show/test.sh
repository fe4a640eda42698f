# halcmd -s: the script-friendly format of show pin, sig and param
cat > host.hal <<'HAL'
loadrt lowpass
loadrt conv_s32_float
net v conv-s32-float.0.out => lowpass.0.in
setp conv-s32-float.0.in -3
setp lowpass.0.gain 0.5
loadusr -w bash ./client.sh
HAL
cat > client.sh <<'SH'
halcmd -s show sig
halcmd -s show pin lowpass
halcmd -s show param lowpass.0.gain
halcmd -s list sig
SH
halrun -f host.hal
echo "status $?"
rm -f host.hal client.sh
