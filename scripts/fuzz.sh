#!/usr/bin/env bash
# Fuzz biotet's readers, surface validation and the pipeline with libFuzzer on the stable
# toolchain: libfuzzer-sys links libFuzzer (built from its C++ source), and the coverage
# instrumentation is LLVM's SanitizerCoverage pass asked for with stable `-C` options (no
# sanitizer runtime, which would need a nightly). Targets: crates/biotet-fuzz/src/lib.rs.
#
#   scripts/fuzz.sh build                     build the instrumented binary
#   scripts/fuzz.sh run SECONDS [TARGET...]   fuzz each target (all by default) for SECONDS
#   scripts/fuzz.sh seeds                     rewrite fuzz/seeds/ (committed)
#   scripts/fuzz.sh list                      the targets
#
# The corpus grows in target/fuzz/corpus/<target> (seeded from fuzz/seeds/<target>); a failing
# input lands in target/fuzz/artifacts/<target>/ and makes `run` exit 1; copy it to
# fuzz/regressions/<target>/ (named after what it caught) and `cargo test -p biotet-fuzz`
# replays it from then on. One line per target goes to target/fuzz/summary.tsv.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
out=${CARGO_TARGET_DIR:-$root/target}/fuzz
# With --target, RUSTFLAGS reach the target's code only, not build scripts and proc macros
# (which would not link without libFuzzer).
host=$(rustc -vV | sed -n 's/^host: //p')
bin=$out/$host/release/biotet-fuzz
targets=$(sed -n '/^pub const TARGETS/,/^];/p' crates/biotet-fuzz/src/lib.rs | grep -o '"[a-z_]*"' | tr -d '"')

build() {
  RUSTFLAGS="--cfg fuzzing -Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares" \
    CARGO_TARGET_DIR=$out cargo build --release --locked --target "$host" --manifest-path fuzz/Cargo.toml
}

run() {
  local secs=$1
  shift
  local list=${*:-$targets}
  local failed=0
  mkdir -p "$out"
  printf 'target\tseconds\texecutions\tcorpus\tfailures\n' >"$out/summary.tsv"
  for t in $list; do
    mkdir -p "$out/corpus/$t" "$out/artifacts/$t"
    local log=$out/$t.log
    local rc=0
    # -timeout: an input running longer is a hang; -rss_limit_mb: more resident memory is an
    # out-of-memory failure (single allocations are capped by biotet_fuzz::CappedAlloc).
    BIOTET_FUZZ_TARGET=$t "$bin" -max_total_time="$secs" -timeout=20 -rss_limit_mb=2048 \
      -print_final_stats=1 -artifact_prefix="$out/artifacts/$t/" \
      "$out/corpus/$t" "fuzz/seeds/$t" >"$log" 2>&1 || rc=$?
    local execs corpus fails
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    corpus=$(find "$out/corpus/$t" -type f | wc -l)
    fails=$(find "$out/artifacts/$t" -type f | wc -l)
    printf '%s\t%s\t%s\t%s\t%s\n' "$t" "$secs" "$execs" "$corpus" "$fails" | tee -a "$out/summary.tsv"
    if [ "$rc" -ne 0 ]; then
      echo "fuzz target $t failed (exit $rc); log: $log" >&2
      grep -E 'panicked|ERROR: libFuzzer|allocation above the cap|Test unit written' "$log" | head -5 >&2 || true
      failed=1
    fi
  done
  return $failed
}

case "${1:-}" in
  build) build ;;
  run)
    # Always: a stale binary would fuzz old code (a no-op build takes a fraction of a second).
    build
    run "${2:-60}" "${@:3}"
    ;;
  seeds) cargo run -q -p biotet-fuzz --example seeds ;;
  list) echo "$targets" ;;
  *)
    sed -n '2,16p' "$0"
    exit 2
    ;;
esac
