#!/usr/bin/env bash
# Coverage-guided fuzzing of crease (libFuzzer through libfuzzer-sys), for CI and by hand.
#
#   scripts/fuzz.sh [TARGET...]     all targets of fuzz/fuzz_targets/ when none is named
#
# Builds the targets with plain cargo on the stable toolchain (the sanitizer-coverage flags that
# cargo-fuzz would pass, no AddressSanitizer: Rust is memory safe, we look for panics, hangs and
# huge allocations), makes a seed corpus for each from ../shared/data and
# crates/crease/tests/bad_input (fuzz/src/bin/seedgen.rs), replays the inputs kept in
# fuzz/regressions/<target>/ (crashes found earlier, once fixed), then fuzzes each target for
# FUZZ_SECONDS, FUZZ_JOBS targets at a time. Exits non-zero naming the target and the input of
# any crash, timeout or out-of-memory.
#
# Environment:
#   FUZZ_SECONDS  fuzzing time per target (default 15: the whole step, build included, about
#                 5 minutes on 2 cores)
#   FUZZ_JOBS     targets fuzzed at once (default: the number of cores)
#   FUZZ_OUT      where seeds, corpora, logs and crash inputs go (default fuzz/target/fuzz-run;
#                 cleared first)
#   CREASE_DATA   the real test data (default ../shared/data)
# A crash input replays with: fuzz/target/<host>/release/<target> <input>
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

FUZZ_SECONDS=${FUZZ_SECONDS:-15}
FUZZ_JOBS=${FUZZ_JOBS:-$(nproc 2>/dev/null || echo 2)}
out=${FUZZ_OUT:-$root/fuzz/target/fuzz-run}
data=${CREASE_DATA:-$root/../shared/data}
if [ ! -d "$data" ]; then
  echo "fuzz: $data is missing: the seed corpus is made from the real test data" >&2
  exit 1
fi

if [ $# -gt 0 ]; then
  targets=("$@")
else
  targets=()
  for f in fuzz/fuzz_targets/*.rs; do
    t=${f##*/}
    targets+=("${t%.rs}")
  done
fi
for t in "${targets[@]}"; do
  if [ ! -f "fuzz/fuzz_targets/$t.rs" ]; then
    echo "fuzz: no target $t (fuzz/fuzz_targets/$t.rs)" >&2
    exit 2
  fi
done

# The flags of `cargo fuzz build --sanitizer none --release --debug-assertions`. An explicit
# --target keeps them off build scripts and proc macros, which cannot link the coverage hooks.
host=$(rustc -vV | sed -n 's/^host: //p')
export CARGO_TARGET_DIR=$root/fuzz/target
unset CARGO_ENCODED_RUSTFLAGS
export RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing"
start=$(date +%s)
echo "fuzz: building ${#targets[@]} targets ($(rustc --version))"
bins=(--bin seedgen --bin decode)
for t in "${targets[@]}"; do bins+=(--bin "$t"); done
cargo build --manifest-path fuzz/Cargo.toml --release --target "$host" "${bins[@]}"
bin=$CARGO_TARGET_DIR/$host/release
echo "fuzz: built in $(($(date +%s) - start)) s"

rm -rf "$out"
mkdir -p "$out/seeds" "$out/tmp"
"$bin/seedgen" "$data" crates/crease/tests/bad_input "$out/seeds"
# Reader targets write their input to a scratch file under here (crease_fuzz::read_as).
export CREASE_FUZZ_TMP=$out/tmp
export RUST_BACKTRACE=1
# One rayon thread: reproducible runs, and two panicking workers cannot race libFuzzer's crash
# handler (which then writes a wrong input); the targets run side by side instead.
export RAYON_NUM_THREADS=1

flags=(-rss_limit_mb=4096 -timeout=10 -max_len=65536)

failed=()
# Inputs kept as regression tests: each runs once and must pass.
for t in "${targets[@]}"; do
  reg=fuzz/regressions/$t
  if [ -d "$reg" ] && [ -n "$(ls -A "$reg")" ]; then
    if ! "$bin/$t" "${flags[@]}" "$reg"/* >"$out/$t.regressions.log" 2>&1; then
      echo "fuzz: FAILED $t: a regression input of $reg crashes again:" >&2
      tail -n 40 "$out/$t.regressions.log" >&2
      failed+=("$t")
    fi
  fi
done

# One target: fuzz for FUZZ_SECONDS; new inputs go to corpus/<t>, crash inputs to artifacts/.
fuzz_one() {
  local t=$1
  mkdir -p "$out/corpus/$t" "$out/artifacts"
  "$bin/$t" "${flags[@]}" -max_total_time="$FUZZ_SECONDS" -print_final_stats=1 \
    -artifact_prefix="$out/artifacts/$t-" "$out/corpus/$t" "$out/seeds/$t" \
    >"$out/$t.log" 2>&1
}

echo "fuzz: ${#targets[@]} targets, ${FUZZ_SECONDS} s each, ${FUZZ_JOBS} at a time"
pids=()
names=()
# Waits for the oldest running target and reports it.
finish_oldest() {
  local t=${names[0]}
  if wait "${pids[0]}"; then
    local runs
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/$t.log" | tail -n 1)
    echo "fuzz: ok $t (${runs:-?} runs)"
  else
    failed+=("$t")
    echo "fuzz: FAILED $t:" >&2
    grep -v -E '^(#|INFO|stat::|WARNING: Failed to find)' "$out/$t.log" | head -n 80 >&2 || true
    local a
    for a in "$out/artifacts/$t-"{crash,timeout,oom}-*; do
      if [ -e "$a" ]; then
        echo "fuzz: $t: input saved as $a (replay: $bin/$t $a)" >&2
      fi
    done
  fi
  pids=("${pids[@]:1}")
  names=("${names[@]:1}")
}
for t in "${targets[@]}"; do
  if [ "${#pids[@]}" -ge "$FUZZ_JOBS" ]; then
    finish_oldest
  fi
  fuzz_one "$t" &
  pids+=($!)
  names+=("$t")
done
while [ "${#pids[@]}" -gt 0 ]; do
  finish_oldest
done
rm -rf "$out/tmp"

echo "fuzz: done in $(($(date +%s) - start)) s"
if [ "${#failed[@]}" -gt 0 ]; then
  echo "fuzz: ${#failed[@]} targets failed: ${failed[*]} (logs and inputs in $out)" >&2
  exit 1
fi
