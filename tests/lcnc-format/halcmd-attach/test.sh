# halcmd in another process attaches to the instance that halrun hosts
cat > host.hal <<'HAL'
loadrt and2
net s and2.0.in0
loadusr -w bash ./client.sh
HAL
cat > client.sh <<'SH'
halcmd setp and2.0.in1 1
halcmd sets s 1
halcmd getp and2.0.in0
halcmd getp and2.0.in1
halcmd -s show sig s
halcmd list pin and2
SH
halrun -f host.hal
echo "status $?"
rm -f host.hal client.sh
