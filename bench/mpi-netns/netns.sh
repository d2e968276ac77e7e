#!/usr/bin/env bash
# Simulated hosts for radiosity-mpi on one machine (issue #15's multi-host benchmark):
# network namespaces joined by veth pairs to a bridge, so that Open MPI's TCP transport
# carries every message between ranks through a kernel network stack, with tc netem's
# rate (and, where the kernel has it, netem's latency) on each host's link. Needs root
# (CAP_NET_ADMIN). Not part of cargo test.
#
#   bench/mpi-netns/netns.sh up HOSTS [RATE [DELAY]]  # e.g. up 4 100mbit; hosts 10.77.0.11 ..
#   bench/mpi-netns/netns.sh down HOSTS
#
# RATE is put on by tc's token bucket (tbf, in every kernel with traffic control); DELAY needs
# netem (sch_netem), which the kernel of the machine these figures come from lacks: `tc
# qdisc add ... netem` says "Error: Specified qdisc kind is unknown." and this script stops.
#
# Host k (1..HOSTS) is the namespace rmpi-hK with address 10.77.0.(10+k)/24 on its veth
# rmpi-vK; the bridge rmpi-br in the root namespace is 10.77.0.1 (where mpirun runs).
# The shaping is put on both ends of each pair (the host's egress and the bridge side's
# egress to it), so a message between two hosts crosses two shaped links, as through a switch.
set -euo pipefail
cmd=${1:?usage: netns.sh up|down HOSTS [RATE [DELAY]]}
hosts=${2:?usage: netns.sh up|down HOSTS [RATE [DELAY]]}
rate=${3:-}
delay=${4:-}
if [ "$cmd" = down ]; then
    for k in $(seq 1 "$hosts"); do
        ip netns del "rmpi-h$k" 2>/dev/null || true
        ip link del "rmpi-v$k" 2>/dev/null || true
    done
    ip link del rmpi-br 2>/dev/null || true
    exit 0
fi
ip link add rmpi-br type bridge
ip addr add 10.77.0.1/24 dev rmpi-br
ip link set rmpi-br up
for k in $(seq 1 "$hosts"); do
    ns="rmpi-h$k"
    ip netns add "$ns"
    ip link add "rmpi-v$k" type veth peer name eth0 netns "$ns"
    ip link set "rmpi-v$k" master rmpi-br up
    ip -n "$ns" addr add "10.77.0.$((10 + k))/24" dev eth0
    ip -n "$ns" link set eth0 up
    ip -n "$ns" link set lo up
    shape=()
    if [ -n "$delay" ]; then
        shape=(netem delay "$delay")
        [ -n "$rate" ] && shape+=(rate "$rate")
    elif [ -n "$rate" ]; then
        # A 256 kB bucket: at 10 Gbit/s and a 4 ms timer tick a smaller one caps the rate.
        shape=(tbf rate "$rate" burst 256kb latency 100ms)
    fi
    if [ ${#shape[@]} -gt 0 ]; then
        ip netns exec "$ns" tc qdisc add dev eth0 root "${shape[@]}"
        tc qdisc add dev "rmpi-v$k" root "${shape[@]}"
    fi
done
