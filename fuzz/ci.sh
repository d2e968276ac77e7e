#!/usr/bin/env bash
# CI's bounded fuzz run (called by .ci/run): builds the targets (a release build of this
# crate alone) and runs each for FUZZ_SECONDS (default 60) from the seed corpus. A crash, a
# timeout or an out-of-memory input makes libFuzzer exit non-zero, and so this script.
set -euo pipefail
cd "$(dirname "$0")"

# libfuzzer-sys compiles libFuzzer's C++ source: it needs a C++ compiler.
if ! command -v c++ >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        echo "installing g++ for libFuzzer"
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -qq >/dev/null
        apt-get install -y -qq --no-install-recommends g++ >/dev/null
    else
        echo "fuzz/ci.sh: a C++ compiler (c++) is needed to build libFuzzer" >&2
        exit 1
    fi
fi

seconds=${FUZZ_SECONDS:-60}
./build.sh
for target in scene_file form_factor_file obj gltf vrml dxf ies points checkpoint; do
    echo "fuzzing $target for $seconds s"
    # libFuzzer's progress lines are many; its final statistics and any crash report are
    # what CI needs, so the log is kept and shown in full only on failure.
    log=$(mktemp)
    if ./run.sh "$target" "$seconds" >"$log" 2>&1; then
        grep -E '^(Done|stat::)' "$log" || true
        rm -f "$log"
    else
        status=$?
        tail -n 80 "$log"
        echo "fuzz target $target failed (exit $status): the input is in fuzz/artifacts/$target/" >&2
        exit "$status"
    fi
done
