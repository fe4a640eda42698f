# setp errors: a missing pin, a value not of the pin's type, an out pin
# linked to a signal; with -k the rest runs and the values are unchanged
cat > setp.hal <<'HAL'
loadrt and2
loadrt conv_s32_float
net o and2.0.out
setp nosuch.pin 1
setp and2.0.in0 maybe
setp conv-s32-float.0.in 1.5
setp conv-s32-float.0.in 99999999999
setp and2.0.in1 1
getp and2.0.in0
getp and2.0.in1
getp conv-s32-float.0.in
HAL
halrun -k -f setp.hal 2> err
echo "halrun -k status $?"
echo "error lines: $(grep -c 'setp.hal:' err)"
halrun -f setp.hal 2> err
echo "halrun status $?"
rm -f setp.hal err
