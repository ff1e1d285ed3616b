#!/usr/bin/env bash
# `make fuzz`: builds the libFuzzer targets of test/fuzz with clang, ASan and UBSan, and runs each
# for FUZZ_SECONDS (default 120) from the checked-in corpus. New inputs go to a scratch corpus under
# the build directory; FUZZ_MERGE=1 merges the ones that add coverage back into test/fuzz/corpus.
# Exit status non-zero on any crash, sanitizer report or broken invariant; the input that caused
# it is kept under <build>/artifacts (copy it to test/fuzz/regressions/<target>/ once fixed).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${FUZZ_BUILD_DIR:-$ROOT/.ws/fuzz}"
SECONDS_PER_TARGET="${FUZZ_SECONDS:-120}"
TARGETS=(parameter_file sample_processing)
CXX_FUZZ="${FUZZ_CXX:-clang++-14}"

cmake -S "$ROOT/test/fuzz" -B "$BUILD" -DCMAKE_CXX_COMPILER="$CXX_FUZZ" > "$BUILD.cmake.log" 2>&1 ||
  { cat "$BUILD.cmake.log"; exit 1; }
cmake --build "$BUILD" -j"$(nproc)"

mkdir -p "$BUILD/artifacts"
status=0
for t in "${TARGETS[@]}"; do
  seeds="$ROOT/test/fuzz/corpus/$t"
  scratch="$BUILD/corpus/$t"
  mkdir -p "$scratch"
  dict=()
  [ -f "$ROOT/test/fuzz/$t.dict" ] && dict=(-dict="$ROOT/test/fuzz/$t.dict")
  regressions=()
  [ -d "$ROOT/test/fuzz/regressions/$t" ] && regressions=("$ROOT/test/fuzz/regressions/$t")
  echo "== $t: ${SECONDS_PER_TARGET} s, seeds $(ls "$seeds" | wc -l)"
  log="$BUILD/$t.log"
  if "$BUILD/${t}_fuzzer" "$scratch" "$seeds" "${regressions[@]}" "${dict[@]}" \
      -max_total_time="$SECONDS_PER_TARGET" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
      -print_final_stats=1 -artifact_prefix="$BUILD/artifacts/$t-" > "$log" 2>&1; then
    grep -E "^#[0-9]+.*DONE|stat::number_of_executed_units|stat::peak_rss_mb|stat::new_units_added" "$log" || true
  else
    status=1
    echo "!! $t FAILED; log $log, artifacts:"
    ls "$BUILD/artifacts" | grep "^$t-" || true
    grep -E "ERROR|invariant|runtime error|SUMMARY" "$log" | head -20 || true
  fi
  if [ "${FUZZ_MERGE:-0}" = "1" ]; then
    "$BUILD/${t}_fuzzer" -merge=1 "$seeds" "$scratch" > "$BUILD/$t.merge.log" 2>&1
    echo "   merged into test/fuzz/corpus/$t: $(ls "$seeds" | wc -l) files"
  fi
done
exit $status
