#!/bin/bash
# A place where the reference's hm2_eth can reach hm2-sim (needs root).
#
#   tests/data/hm2/netns.sh up [BOARD]     the namespace, veth pair and MAC
#   tests/data/hm2/netns.sh down           remove them
#
# hm2_eth reads the card's MAC address and sets a static ARP entry for it,
# which the loopback interface refuses (SIOCSARP: Invalid argument).  So
# the card lives at 10.96.7.2 in the network namespace "hm2sim", behind a
# veth pair (hm2sim0, 10.96.7.1, on this side; hm2sim1 in the namespace)
# whose far end carries the MAC the board profile reports.  Then:
#
#   ip netns exec hm2sim hm2-sim --board BOARD --address 10.96.7.2 &
#   halrun: loadrt hm2_eth board_ip=10.96.7.2 ...
#
# Used by tests/data/hm2/regen.sh (and usable by a benchmark).
set -euo pipefail
ns=hm2sim
case "${1:-}" in
    up)
        if ! ip netns list | grep -qw "$ns"; then
            ip netns add "$ns"
            ip link add hm2sim0 type veth peer name hm2sim1 netns "$ns"
            ip addr add 10.96.7.1/24 dev hm2sim0
            ip link set hm2sim0 up
            ip -n "$ns" addr add 10.96.7.2/24 dev hm2sim1
            ip -n "$ns" link set hm2sim1 up
            ip -n "$ns" link set lo up
        fi
        if [ -n "${2:-}" ]; then
            mac=$(cd /tmp && "${HM2SIM_PYTHON:-python3}" -c \
                "from halsdk.drivers.hm2sim import profile; print(profile('$2').mac.hex(':'))")
            ip -n "$ns" link set hm2sim1 address "$mac"
            ip neigh flush dev hm2sim0
        fi ;;
    down)
        ip netns del "$ns" 2>/dev/null || true ;;
    *)
        sed -n 2,16p "$0"; exit 2 ;;
esac
