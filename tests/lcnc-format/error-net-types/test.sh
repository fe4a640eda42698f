# net and linking errors: types that do not match, two writers, a
# signal of one type linked to a pin of another (each command links one
# pin, or fails on its first pin, so that no command is half done)
cat > net.hal <<'HAL'
loadrt and2 count=2
loadrt conv_s32_float
newsig a s32
linksp a and2.0.out
net a2 and2.0.out
net b and2.1.out and2.0.out
newsig f float
linksp f and2.1.in0
net c and2.0.in0 and2.1.in0
show sig
HAL
halrun -k -f net.hal 2> err
echo "halrun -k status $?"
echo "error lines: $(grep -c 'net.hal:' err)"
rm -f net.hal err
