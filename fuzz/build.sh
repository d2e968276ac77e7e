#!/usr/bin/env bash
# Builds the fuzz targets with libFuzzer on the stable toolchain: the sanitizer-coverage
# flags that cargo-fuzz passes, given to rustc directly (see README.md). Extra arguments go to
# cargo build (for instance --bin scene_file). The binaries land in
# $CARGO_TARGET_DIR (default fuzz/target)/HOST/release/, HOST being the host triple: naming the
# target keeps RUSTFLAGS off the build scripts and proc macros, which would not link with
# the coverage hooks (libFuzzer provides them only to the fuzz binaries). Not --locked: the
# committed Cargo.lock pins every version, and a dependency the library gains later is added
# to it rather than failing CI's fuzz build (pass --locked to refuse that).
set -euo pipefail
cd "$(dirname "$0")"
export RUSTFLAGS="${RUSTFLAGS:-} -Cpasses=sancov-module \
 -Cllvm-args=-sanitizer-coverage-level=4 \
 -Cllvm-args=-sanitizer-coverage-inline-8bit-counters \
 -Cllvm-args=-sanitizer-coverage-pc-table \
 -Cllvm-args=-sanitizer-coverage-trace-compares \
 --cfg fuzzing -Cdebug-assertions -Coverflow-checks"
host=$(rustc -vV | sed -n "s/^host: //p")
exec cargo build --release --target "$host" "$@"
