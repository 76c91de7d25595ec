#!/bin/bash
# Builds the fuzz targets with clang, libFuzzer and AddressSanitizer in build-fuzz/ and runs each
# for a bounded time: the URDF parser on tests/fuzz/corpus, then the OBJ reader on
# tests/fuzz/obj_corpus and the JSON parser on tests/fuzz/json_corpus for half as long each (the
# JSON parser with at most 1 s per input of up to 256 KB, so that a superlinear parse fails), and
# PLY files through the mesh loader on tests/fuzz/ply_corpus, as long, under a 2 GB RSS limit.
# Exits non-zero when a fuzzer finds a crash, a leak or a sanitizer error. Usage: scripts/run_fuzz.sh [seconds (default 60)] [extra libFuzzer flags...]
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
build="${PARTSIM_FUZZ_BUILD_DIR:-$root/build-fuzz}"
seconds="${1:-60}"
shift || true

# configure and build only the fuzz target; partsim_core is instrumented too
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_CXX_FLAGS="-fsanitize=address,fuzzer-no-link -fno-omit-frame-pointer" \
  -DPARTSIM_FUZZ=ON -DPARTSIM_BUILD_PYTHON=OFF -DPARTSIM_BUILD_TESTS=OFF -DPARTSIM_WERROR=OFF \
  -DPARTSIM_BUILD_BENCH=OFF >"$build.configure.log" 2>&1 ||
  { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j2 --target urdf_fuzz obj_fuzz json_fuzz ply_fuzz

# run on a scratch copy of the corpus so that new inputs stay out of the repository unless
# they are copied back on purpose (crash files land in $build/artifacts)
mkdir -p "$build/artifacts"
cd "$build"
extra=("$@")
# fuzz TARGET CORPUS WORK LEAKS SECONDS ARTIFACT_PREFIX [libFuzzer flags...]: TARGET on a
# scratch copy WORK of tests/fuzz/CORPUS, with leak checking LEAKS (1 or 0) unless ASAN_OPTIONS
# says otherwise, then the caller's extra flags
fuzz() {
  local target="$1" corpus="$2" work="$build/$3" leaks="$4" time="$5" prefix="$6"
  shift 6
  mkdir -p "$work"
  cp -n "$root/tests/fuzz/$corpus"/* "$work"/ 2>/dev/null || true
  ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=$leaks}" "$build/tests/fuzz/$target" "$work" \
    -max_total_time="$time" "$@" -artifact_prefix="$build/artifacts/$prefix" \
    -print_final_stats=1 "${extra[@]}"
}
half=$(((seconds + 1) / 2))
fuzz urdf_fuzz corpus corpus 1 "$seconds" "" -max_len=16384 -timeout=10 -rss_limit_mb=4096 \
  -dict="$root/tests/fuzz/urdf.dict"
fuzz obj_fuzz obj_corpus obj_corpus 1 "$half" obj- -max_len=16384 -timeout=10 -rss_limit_mb=4096
fuzz json_fuzz json_corpus json_corpus 1 "$half" json- -max_len=262144 -timeout=1 \
  -rss_limit_mb=4096
# PLY headers through the mesh loader: a count beyond the file would allocate past the RSS limit.
# No leak check: assimp 5.2.5's PLY reader leaks 1.3 KB on some files it refuses
fuzz ply_fuzz ply_corpus ply_corpus 0 "$half" ply- -max_len=4096 -timeout=10 -rss_limit_mb=2048
