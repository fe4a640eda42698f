#!/bin/bash
# Regenerate the reference's golden listings of the simulated Mesa cards.
#
#   sudo tests/data/hm2/regen.sh [BOARD...]      (default: every profile)
#
# For each board profile of hm2-sim (drivers/hm2sim/profiles.py) this runs
# the reference's hostmot2 + hm2_eth (LinuxCNC 2.9, ../shared/tools/reference)
# against `hm2-sim --board BOARD` and writes tests/data/hm2/BOARD/:
#   load.hal        the HAL file (loadrt hostmot2, hm2_eth, a servo thread,
#                   show pin/param/funct)
#   load.txt        what the reference printed (its stdout and stderr)
#   show-pin.txt, show-param.txt, show-funct.txt   the listings
#   packets.txt     the LBP16 conversation, decoded: the load, the first
#                   servo cycles and the unload (hm2-sim --log; the time
#                   in brackets is how long the card took to reply)
#   configs.txt     what the reference prints for config strings that it
#                   accepts or refuses against this card (one load each)
#
# Why a network namespace (netns.sh): hm2_eth reads the card's MAC address
# and sets a static ARP entry for the card (SIOCSARP), which the loopback
# interface refuses (EINVAL).  So the card lives at 10.96.7.2 in the
# network namespace hm2sim, behind a veth pair (10.96.7.1 on this side)
# whose far end carries the MAC the profile reports.  Needs root;
# hm2_eth also adds an empty iptables chain hm2-eth-rules-output and a jump
# to it from OUTPUT at each load (the script removes the jumps it caused at
# the end), and removes its ARP entry when it unloads.  `netns.sh down`
# removes the namespace and the veth pair.
#
# Environment: HM2SIM_PYTHON a Python with halsdk installed (default
# python3), PERIOD the servo period in ns (default 1000000), KEEP=1 keeps
# the work folder (with the whole packet log), REFERENCE the reference
# wrapper (default ../shared/tools/reference beside the checkout).
#
# The names, types and directions of the listings are the golden part;
# some values depend on timing (watchdog.has_bit when the non-realtime
# reference thread was late by more than the watchdog's 5 ms, the packet
# error counters, encoder timestamps, read-request.time).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
python=${HM2SIM_PYTHON:-python3}
ns=hm2sim
card_ip=10.96.7.2
boards=("$@")
configs=("num_stepgens=6" "num_encoders=2" "num_pwmgens=1" "num_pwmgens=2"
         "sserial_port_0=0000" "num_sserials=1" "bogus=1"
         "num_stepgens=3 num_encoders=0 num_pwmgens=0" "num_stepgens=-1"
         "enable_raw" "num_leds=1")
[ ${#boards[@]} -gt 0 ] || boards=(7i96s 7i92)
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin

"$here/netns.sh" up

# hm2_eth adds a jump to its (empty) chain to OUTPUT at each load, even
# when there is one: take the ones these runs add away at the end
jumps() { iptables -S OUTPUT 2>/dev/null | grep -c -- "-j hm2-eth-rules-output" || true; }
jumps_before=$(jumps)
restore_jumps() {
    local n
    n=$(jumps)
    while [ "$n" -gt "$jumps_before" ]; do
        iptables -D OUTPUT -j hm2-eth-rules-output || break
        n=$((n - 1))
    done
}
trap restore_jumps EXIT

for board in "${boards[@]}"; do
    out="$here/$board"
    mkdir -p "$out"
    rm -f "$out"/*.txt
    config=$(cd /tmp && "$python" -c "from halsdk.drivers.hm2sim import profile; print(profile('$board').config)")
    HM2SIM_PYTHON="$python" "$here/netns.sh" up "$board"
    work=$(mktemp -d /tmp/hm2sim-regen.XXXXXX)
    chmod 755 "$work"
    name="hm2_$board.0"
    cat > "$out/load.hal" <<HAL
# hostmot2 + hm2_eth against hm2-sim --board $board (tests/data/hm2/regen.sh)
loadrt hostmot2
loadrt hm2_eth board_ip=$card_ip config="$config"
loadrt threads name1=servo-thread period1=${PERIOD:-1000000}
addf $name.read servo-thread
addf $name.write servo-thread
start
loadusr -w sleep 0.2
stop
show pin
show param
show funct
HAL
    cp "$out/load.hal" "$work/"
    # hm2_eth gives the first replies after loading only a few hundred
    # microseconds (a real card answers in less): the card runs with
    # realtime scheduling, and a load that timed out on a busy machine
    # is tried again
    for attempt in 1 2 3 4 5; do
        rm -f "$work/packets.txt" "$work/sim.txt"
        (cd /tmp && exec ip netns exec "$ns" chrt -f 20 "$python" \
            -m halsdk.drivers.hm2sim --board "$board" --address "$card_ip" \
            --log "$work/packets.txt" > "$work/sim.txt" 2>&1) &
        sim=$!
        for _ in $(seq 50); do
            grep -q "on UDP" "$work/sim.txt" 2>/dev/null && break
            sleep 0.1
        done
        set +e
        (cd "$work" && flock /tmp/halsdk-reference.lock \
            "${REFERENCE:-$root/../shared/tools/reference}" halrun -f load.hal \
            > halrun.txt 2>&1)
        rc=$?
        set -e
        kill "$sim"; wait "$sim" 2>/dev/null || true
        if [ $rc -eq 0 ] && grep -q ": registered" "$work/halrun.txt"; then
            # a clean run if it can be had: no lost datagram, no bite
            if grep -q "packet-error-total$" "$work/halrun.txt" &&
               grep -q "0x00000000  $name.packet-error-total" "$work/halrun.txt" &&
               ! grep -q "Watchdog has bit" "$work/halrun.txt"; then
                break
            fi
            cp "$work/halrun.txt" "$work/registered.txt"
            cp "$work/packets.txt" "$work/registered-packets.txt"
            echo "$board: attempt $attempt: loaded, with lost datagrams or a bite"
        else
            echo "$board: attempt $attempt failed:" \
                "$(grep -m1 -i 'error' "$work/halrun.txt" || true)"
        fi
        sleep 2
    done
    if ! grep -q ": registered" "$work/halrun.txt" && [ -f "$work/registered.txt" ]; then
        cp "$work/registered.txt" "$work/halrun.txt"
        cp "$work/registered-packets.txt" "$work/packets.txt"
        rc=0
    fi
    # the listings, split at their headings; the rest is what the load printed
    awk -v dir="$out" '
        /^Component Pins:/      { f = dir "/show-pin.txt" }
        /^Parameters:/          { f = dir "/show-param.txt" }
        /^Exported Functions:/  { f = dir "/show-funct.txt" }
        f && /^$/               { print > f; f = ""; next }
        f { print > f; next }
        { print > (dir "/load.txt") }' "$work/halrun.txt"
    # the load and the first servo cycles, then the unload
    total=$(wc -l < "$work/packets.txt")
    {
        head -n 600 "$work/packets.txt"
        if [ "$total" -gt 620 ]; then
            echo "... ($((total - 620)) lines of later servo cycles left out) ..."
            tail -n 20 "$work/packets.txt"
        else
            tail -n +601 "$work/packets.txt"
        fi
    } > "$out/packets.txt"
    echo "$board: reference exit status $rc (attempt $attempt)"
    if [ -n "${KEEP:-}" ]; then echo "kept $work"; else rm -rf "$work"; fi

    # config strings the reference accepts or refuses against this card
    # (the I/O pin table, already in load.txt, left out)
    work=$(mktemp -d /tmp/hm2sim-regen.XXXXXX)
    chmod 755 "$work"
    (cd /tmp && exec ip netns exec "$ns" chrt -f 20 "$python" \
        -m halsdk.drivers.hm2sim --board "$board" --address "$card_ip" \
        > "$work/sim.txt" 2>&1) &
    sim=$!
    for _ in $(seq 50); do
        grep -q "on UDP" "$work/sim.txt" 2>/dev/null && break
        sleep 0.1
    done
    : > "$out/configs.txt"
    for cfg in "${configs[@]}"; do
        printf 'loadrt hostmot2\nloadrt hm2_eth board_ip=%s config="%s"\n' \
            "$card_ip" "$cfg" > "$work/config.hal"
        chmod 644 "$work/config.hal"
        for attempt in 1 2 3 4 5; do
            set +e
            (cd "$work" && flock /tmp/halsdk-reference.lock \
                "${REFERENCE:-$root/../shared/tools/reference}" halrun \
                -f config.hal > halrun.txt 2>&1)
            rc=$?
            set -e
            grep -q "Resource temporarily unavailable" "$work/halrun.txt" || break
            sleep 2
        done
        {
            echo "=== config=\"$cfg\" (exit status $rc)"
            grep -v "IO Pin" "$work/halrun.txt"
        } >> "$out/configs.txt"
    done
    kill "$sim"; wait "$sim" 2>/dev/null || true
    rm -rf "$work"
    echo "$board: ${#configs[@]} config strings in configs.txt"
done
