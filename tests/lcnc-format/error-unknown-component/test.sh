# loadrt of a component that does not exist fails: halrun stops at that
# line with a non-zero status and nothing after it runs
cat > bad.hal <<'HAL'
loadrt and2
loadrt nosuchcomponent_xyz
loadrt or2
HAL
halrun -f bad.hal > out 2> err
echo "halrun status $?"
# the message names the component
grep -c nosuchcomponent_xyz err > /dev/null && echo "message names the component"
# -k keeps going after the failed line
echo 'loadrt and2
loadrt nosuchcomponent_xyz
loadrt or2
list pin' > bad-k.hal
halrun -k -f bad-k.hal 2> err
echo "halrun -k status $?"
rm -f bad.hal bad-k.hal out err
