#!/bin/sh
# Regenerates the stored golden images from the current code (one run) and
# shows what changed. Review the new PNGs before committing them.
#
# usage: scripts/promote-goldens.sh [BUILD_DIR]   (default: build)
# The golden tests run on OSMesa unless BUNDLEBAKE_TEST_BACKEND=egl.
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-"$root/build"}
cmake --build "$build" --target golden_tests -j2
BUNDLEBAKE_PROMOTE_GOLDENS=1 "$build/tests/golden_tests" --gtest_filter='RenderGolden.CornellBoxMatchesGolden'
# the promoted golden must pass the comparison it was made for
"$build/tests/golden_tests" --gtest_filter='RenderGolden.*'
git -C "$root" status --short -- assets/goldens 2>/dev/null || true
