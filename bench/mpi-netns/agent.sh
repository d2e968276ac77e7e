#!/usr/bin/env bash
# mpirun's launch agent (--mca plm_rsh_agent) for the namespaces of netns.sh: in place of
# ssh HOST COMMAND, runs COMMAND in the namespace whose host has address HOST
# (10.77.0.(10+k) -> rmpi-hk). Open MPI passes the host first, then the orted command line.
set -euo pipefail
host=$1
shift
k=$(( ${host##*.} - 10 ))
exec ip netns exec "rmpi-h$k" /bin/sh -c "$*"
