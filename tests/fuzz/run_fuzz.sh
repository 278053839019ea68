#!/bin/sh
# Runs the glTF/glb loader fuzzer (built by tests/fuzz/CMakeLists.txt) from the
# seed corpus (tests/fuzz/seeds, tests/corpus/gltf): new inputs go to a
# scratch directory, never into the source tree; a crash, sanitizer report or
# leak fails the run and leaves the input as crash-* in the scratch directory
# (kept, and printed, on failure).
# With the dictionary tests/fuzz/gltf.dict (glTF keys, .glb tags).
# Usage: run_fuzz.sh FUZZER SOURCE_DIR [libFuzzer options...]
#   ctest (gltf_fuzz_short): -runs=40000 -seed=1
#   longer by hand:          run_fuzz.sh <build>/fuzz/gltf_fuzzer . -max_total_time=1200
set -u
fuzzer=$1 source=$2
shift 2
if [ ! -x "$fuzzer" ]; then
    echo "gltf fuzzer not built ($fuzzer): install clang and libclang-rt-14-dev (scripts/install-deps.sh) and rebuild"
    exit 1
fi
scratch=$(mktemp -d "${TMPDIR:-/tmp}/bundlebake-fuzz-XXXXXX") || exit 1
mkdir -p "$scratch/corpus"
cd "$scratch" || exit 1
# -timeout: one input may take at most 10 s; -rss_limit_mb: 2 GB; inputs up to 64 KiB
"$fuzzer" -max_len=65536 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -dict="$source/tests/fuzz/gltf.dict" "$@" \
    "$scratch/corpus" "$source/tests/fuzz/seeds" "$source/tests/corpus/gltf" >"$scratch/log.txt" 2>&1
code=$?
grep -E '^(#[0-9]+ +(INITED|DONE)|stat::number_of_executed_units|stat::peak_rss_mb|Done [0-9]+ runs)' "$scratch/log.txt"
if [ "$code" -ne 0 ]; then
    tail -60 "$scratch/log.txt"
    echo "gltf fuzzer FAILED (exit $code); inputs and log kept in $scratch"
    exit 1
fi
rm -rf "$scratch"
echo "gltf fuzzer: no crash, no sanitizer report, no leak"
