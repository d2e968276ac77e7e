#!/usr/bin/env bash
# Runs one fuzz target for a bounded time: fuzz/run.sh TARGET SECONDS [libFuzzer options...]
#
# TARGET is scene_file, form_factor_file, obj, gltf, vrml, dxf, ies, points or checkpoint. The binary must have been built by build.sh
# (same CARGO_TARGET_DIR). The target grows its corpus in fuzz/work/TARGET (ignored by git),
# starting from the seeds in fuzz/corpus/TARGET, which it only reads; a crashing input is
# written to fuzz/artifacts/TARGET/ and the script exits non-zero.
set -euo pipefail
cd "$(dirname "$0")"
target=${1:?usage: run.sh TARGET SECONDS [libFuzzer options...]}
seconds=${2:?usage: run.sh TARGET SECONDS [libFuzzer options...]}
shift 2
case "$target" in
    scene_file) options=(-dict=scene.dict -max_len=8192) ;;
    form_factor_file) options=(-dict=form_factor.dict -max_len=4096) ;;
    obj) options=(-dict=obj.dict -max_len=8192) ;;
    gltf) options=(-dict=gltf.dict -max_len=16384) ;;
    vrml) options=(-dict=vrml.dict -max_len=8192) ;;
    dxf) options=(-dict=dxf.dict -max_len=8192) ;;
    ies) options=(-dict=ies.dict -max_len=8192) ;;
    points) options=(-max_len=4096) ;;
    checkpoint) options=(-dict=checkpoint.dict -max_len=4096) ;;
    *) echo "unknown target $target (scene_file, form_factor_file, obj, gltf, vrml, dxf, ies, points or checkpoint)" >&2; exit 2 ;;
esac
host=$(rustc -vV | sed -n "s/^host: //p")
binary="${CARGO_TARGET_DIR:-target}/$host/release/$target"
mkdir -p "work/$target" "artifacts/$target"
# -timeout: one input may take at most 10 s (a hang is a finding too);
# -rss_limit_mb: more than 2 GB for one input is a finding (the harness bounds keep the
# work of a valid scene to milliseconds); -malloc_limit_mb likewise for one allocation.
exec "$binary" "work/$target" "corpus/$target" \
    "${options[@]}" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -malloc_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="artifacts/$target/" "$@"
