#!/usr/bin/env bash
# Fuzzes the scene parser and the STL reader with libFuzzer (clang,
# -fsanitize=fuzzer,address,undefined). Builds only what the targets need
# (tests/fuzz/CMakeLists.txt) into its own folder, then runs each target in turn on
# one core for SECONDS.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]     # default: 60 s, every target
#   scripts/fuzz.sh 600 scene_parser          # ten minutes on the scene parser
#   scripts/fuzz.sh 0                         # build only
#
# Targets: scene_parser, stl_reader. Each starts from its seed corpus in
# tests/fuzz/corpus/<scene|stl>/ (read only) and keeps what it discovers in
# <build>/corpus/<target>/, so later runs continue from there. A crash, sanitizer
# report, hang (> 10 s per input), or an allocation above the limits below stops the
# run; the input is saved as <build>/artifacts/<target>/crash-* (or leak-, timeout-,
# oom-) and the script exits 1. Reproduce with: <build>/<target>_fuzz FILE.
# Once fixed, copy the input into the target's seed corpus as a regression.
#
#   GRAINFLOW_FUZZ_BUILD_DIR   build folder (default: <repo>/build-fuzz)
#   CXX                        a clang++ with libFuzzer (default: clang++)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${GRAINFLOW_FUZZ_BUILD_DIR:-$ROOT/build-fuzz}"
SECONDS_PER_TARGET="${1:-60}"
shift || true
TARGETS=("$@")
[ "${#TARGETS[@]}" -gt 0 ] || TARGETS=(scene_parser stl_reader)

log() { printf '[fuzz] %s\n' "$*"; }

declare -A SEEDS=([scene_parser]=scene [stl_reader]=stl)
# Longest input tried: a few kB covers every section of a scene and a few hundred
# ASCII triangles; longer inputs only slow the search down.
declare -A MAX_LEN=([scene_parser]=8192 [stl_reader]=4096)

for t in "${TARGETS[@]}"; do
  [ -n "${SEEDS[$t]:-}" ] || { echo "fuzz.sh: unknown target '$t'; allowed: ${!SEEDS[*]}" >&2; exit 2; }
done

GENERATOR=()
command -v ninja >/dev/null && GENERATOR=(-G Ninja)
log "building in $BUILD"
mkdir -p "$BUILD"
if ! { cmake -S "$ROOT/tests/fuzz" -B "$BUILD" "${GENERATOR[@]}" -DCMAKE_BUILD_TYPE=None \
         -DCMAKE_CXX_COMPILER="${CXX:-clang++}" &&
       cmake --build "$BUILD" --target "${TARGETS[@]/%/_fuzz}" -- -j2; } >"$BUILD/build.log" 2>&1; then
  cat "$BUILD/build.log" >&2
  log "build failed (log: $BUILD/build.log)"
  exit 1
fi
[ "$SECONDS_PER_TARGET" != 0 ] || { log "built ${TARGETS[*]/%/_fuzz}"; exit 0; }

rc=0
for t in "${TARGETS[@]}"; do
  corpus="$BUILD/corpus/$t"
  artifacts="$BUILD/artifacts/$t/"
  mkdir -p "$corpus" "$artifacts"
  # The format's keywords (scene keys and model names; STL keywords) as a dictionary.
  dict=("-dict=$ROOT/tests/fuzz/${SEEDS[$t]}.dict")
  log "$t: ${SECONDS_PER_TARGET} s"
  # -malloc_limit_mb: no single allocation may exceed 512 MB, however the input lies
  # about its size; -rss_limit_mb: the whole process stays under 2 GB.
  if ! "$BUILD/${t}_fuzz" "$corpus" "$ROOT/tests/fuzz/corpus/${SEEDS[$t]}" \
        -max_total_time="$SECONDS_PER_TARGET" -timeout=10 -rss_limit_mb=2048 \
        -malloc_limit_mb=512 -max_len="${MAX_LEN[$t]}" -artifact_prefix="$artifacts" "${dict[@]}" \
        -print_final_stats=1 >"$BUILD/$t.log" 2>&1; then
    rc=1
    log "$t: FAILED; input saved in $artifacts, log in $BUILD/$t.log:"
    grep -E "ERROR|SUMMARY|==[0-9]+==|Test unit written" "$BUILD/$t.log" | head -20 || true
  fi
  grep -E "^#[0-9]+.*(DONE|cov:)" "$BUILD/$t.log" | tail -1 | sed "s/^/[fuzz] $t: /" || true
  grep -E "^stat::(number_of_executed_units|peak_rss_mb|new_units_added)" "$BUILD/$t.log" |
    sed "s/^/[fuzz] $t: /" || true
done
exit "$rc"
