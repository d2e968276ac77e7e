#!/usr/bin/env bash
# One radiosity-mpi run over the simulated hosts of netns.sh, with what BENCHMARKS.md
# records: wall time (/usr/bin/time around mpirun), each rank's CPU time and peak memory
# (/usr/bin/time around each rank: mpirun's own rusage does not include the ranks, which
# run under the daemons the agents start), the program's own summary line, and the bytes each
# host's link carried (the bridge side's counters: rx = what the host sent, tx = what it
# received), TCP/IP headers included. Needs root. Not part of cargo test.
#
#   bench/mpi-netns/run.sh HOSTS BINARY OUT.ff radiosity-mpi-arguments...
#
# One rank a host (ranks 0..HOSTS-1 on hosts 1..HOSTS), one rayon thread a rank, and only
# Open MPI's TCP transport (btl tcp,self) on the hosts' subnet, for the messages between
# ranks and for mpirun's own control traffic (oob) alike.
set -euo pipefail
rm -f "${3:?}"
hosts=${1:?usage: run.sh HOSTS BINARY OUT.ff ARGS...}
binary=${2:?}
out=${3:?}
shift 3
here=$(cd "$(dirname "$0")" && pwd)
list=$(for k in $(seq 1 "$hosts"); do printf '10.77.0.%d:1,' $((10 + k)); done)
counters() {
    for k in $(seq 1 "$hosts"); do
        ip -s -j link show "rmpi-v$k" | python3 -c \
            "import json,sys; s=json.load(sys.stdin)[0]['stats64']; print($k, s['rx']['bytes'], s['tx']['bytes'])"
    done
}
before=$(counters)
/usr/bin/time -f "wall %e s, user %U s, sys %S s, maxrss %M KB" \
    mpirun --allow-run-as-root --oversubscribe -np "$hosts" --host "${list%,}" \
    --mca plm_rsh_agent "$here/agent.sh" \
    --mca btl tcp,self --mca btl_tcp_if_include 10.77.0.0/24 \
    --mca oob_tcp_if_include 10.77.0.0/24 \
    -x RAYON_NUM_THREADS=1 \
    sh -c 'exec /usr/bin/time -f "rank $OMPI_COMM_WORLD_RANK: user %U s, sys %S s, maxrss %M KB" "$0" "$@"' \
    "$binary" "$@" -o "$out" 2>&1 | grep -E "^(form factors: [0-9]+ rows|wall|rank|wrote|error)" || true
after=$(counters)
paste <(echo "$before") <(echo "$after") | while read -r k rx0 tx0 _ rx1 tx1; do
    echo "host $k (rank $((k - 1))): sent $((rx1 - rx0)) bytes, received $((tx1 - tx0)) bytes"
done
