#!/usr/bin/env bash
# bench/record_outputs.sh BIN OUTDIR: every output of BIN on the examples (building.scene left out: too
# big) and the built-in Cornell box, then OUTDIR.sha256 with the sha256 of each output.
#   solve SCENE -o OUTDIR/NAME-METHOD-SOLVER.csv   for each --method and --solver
#   render SCENE -o OUTDIR/NAME.png                at default settings
# A combination that fails (a refusal, e.g. for memory) leaves its stderr in
# OUTDIR/NAME-METHOD-SOLVER.refused instead, hashed like any output.
# Also (the scene-file writer and the overrides): generate building at the small example's
# parameters, and the built-in box solved and rendered with --max-area/--steps overrides
# (coarser than its own settings). Times go to OUTDIR/times.log (not hashed).
# SKIP (environment): space-separated NAME-METHOD-SOLVER combinations to leave out.
set -u
BIN=$(readlink -f "$1")
OUT=$(readlink -m "$2")
REPO=${REPO:-$(cd "$(dirname "$0")/.." && pwd)}
METHODS="area contour analytic hemicube montecarlo"
SOLVERS="auto gauss-seidel lu progressive hierarchical"
SKIP=${SKIP:-}
mkdir -p "$OUT"
: > "$OUT/times.log"

# run NAME OUTFILE ARGS...: runs BIN ARGS, timing it; on failure keeps stderr as NAME.refused.
run() {
    local name=$1 out=$2
    shift 2
    local t0=$(date +%s.%N)
    if ! "$BIN" "$@" 2> "$OUT/$name.stderr"; then
        mv "$OUT/$name.stderr" "$OUT/$name.refused"
        rm -f "$out"
    else
        rm -f "$OUT/$name.stderr"
    fi
    local t1=$(date +%s.%N)
    printf '%-45s %8.2f s\n' "$name" "$(echo "$t1 - $t0" | bc)" >> "$OUT/times.log"
}

scenes="builtin"
for f in "$REPO"/examples/*.scene; do
    n=$(basename "$f" .scene)
    [ "$n" = building ] && continue
    scenes="$scenes $n"
done

cd "$OUT"
for name in $scenes; do
    if [ "$name" = builtin ]; then file=(); else file=("$REPO/examples/$name.scene"); fi
    for m in $METHODS; do
        for s in $SOLVERS; do
            id="$name-$m-$s"
            case " $SKIP " in *" $id "*) continue ;; esac
            run "$id" "$OUT/$id.csv" solve "${file[@]}" --quiet --method "$m" --solver "$s" -o "$OUT/$id.csv"
        done
    done
    run "$name-render" "$OUT/$name.png" render "${file[@]}" --quiet -o "$OUT/$name.png"
done
# The overrides, and the writer.
run builtin-override-solve "$OUT/builtin-override.csv" solve --quiet --max-area 4000 --steps 3 -o "$OUT/builtin-override.csv"
run builtin-override-hier "$OUT/builtin-override-hier.csv" solve --quiet --max-area 4000 --solver hierarchical -o "$OUT/builtin-override-hier.csv"
run builtin-override-render "$OUT/builtin-override.png" render --quiet --max-area 4000 --steps 1 -o "$OUT/builtin-override.png"
run generate "$OUT/generated.scene" generate building --floors 1 --rooms-x 2 --rooms-z 2 --max-area 2 -o "$OUT/generated.scene"

(cd "$OUT" && find . -type f ! -name times.log -printf '%P\n' | LC_ALL=C sort | xargs sha256sum) > "$OUT.sha256"
echo "$(wc -l < "$OUT.sha256") outputs hashed into $OUT.sha256"
