#!/bin/sh
# The suite fails on a machine without GL: with context creation forced to
# fail (BUNDLEBAKE_FORCE_NO_GL=1, headless/platform.cpp), GL tests of both
# kinds (the shared fixture's BB_REQUIRE_GL and a test that makes its own
# context) must FAIL, not skip or pass, and the CLI must refuse to bake in one
# line. This script passes only when all of that happens.
# Usage: fails_without_gl.sh GL_TESTS_BINARY BUNDLEBAKE_CLI SCENE
set -u
gl_tests=$1 cli=$2 scene=$3
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
status=0

BUNDLEBAKE_FORCE_NO_GL=1 "$gl_tests" --gtest_filter='GlCompute.SaxpyUnderEgl:Rgb9e5*:BundleOverflow.*' >"$tmp/gtest.txt" 2>&1
gcode=$?
if [ "$gcode" -eq 0 ]; then
    echo "FAIL: gl_tests exited 0 without a GL context"; status=1
fi
if ! grep -q '^\[  PASSED  \] 0 tests' "$tmp/gtest.txt"; then
    echo "FAIL: some GL test passed without a GL context"; status=1
fi
if grep -q '^\[  SKIPPED \]' "$tmp/gtest.txt"; then
    echo "FAIL: a GL test skipped instead of failing"; status=1
fi
failed=$(grep -c '^\[  FAILED  \] [A-Za-z0-9_]*\.[A-Za-z0-9_]* (' "$tmp/gtest.txt")
if [ "$failed" -lt 3 ]; then
    echo "FAIL: expected at least 3 failed GL tests, got $failed"; status=1
fi
if ! grep -q 'BUNDLEBAKE_FORCE_NO_GL' "$tmp/gtest.txt"; then
    echo "FAIL: the failures do not say why (no context)"; status=1
fi

BUNDLEBAKE_FORCE_NO_GL=1 "$cli" bake "$scene" -o "$tmp/out" --uv-layout asset --resolution 16 --directions 4 \
    --no-progress >"$tmp/cli.out" 2>"$tmp/cli.err"
code=$?
if [ "$code" -eq 0 ] || [ "$(wc -l <"$tmp/cli.err")" -ne 1 ] || [ -e "$tmp/out/lightmap_0.exr" ]; then
    echo "FAIL: bundlebake bake without GL: exit $code, stderr:"; cat "$tmp/cli.err"; status=1
fi

echo "--- gl_tests with BUNDLEBAKE_FORCE_NO_GL=1 (exit $gcode):"
grep -E '^\[  (FAILED|PASSED|SKIPPED) |no (egl|osmesa|GL) context' "$tmp/gtest.txt" | head -20
echo "--- bundlebake bake (exit $code): $(cat "$tmp/cli.err")"
[ "$status" -eq 0 ] && echo "OK: without GL the GL tests fail ($failed failed) and the CLI refuses"
exit $status
