# halrun -i INI: [SECTION]KEY substitution in the HAL file
cat > m.ini <<'INI'
[THREADS]
PERIOD = 2000000
[FILTER]
GAIN = 0.75
NAME = lp
PIN = lp.gain
INI
cat > m.hal <<'HAL'
loadrt threads name1=servo period1=[THREADS]PERIOD
loadrt lowpass names=[FILTER]NAME
setp [FILTER]PIN [FILTER]GAIN
getp lp.gain
getp [FILTER]PIN
list thread
HAL
halrun -i m.ini -f m.hal
echo "status $?"
rm -f m.ini m.hal
