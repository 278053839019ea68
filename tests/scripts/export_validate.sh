#!/bin/sh
# Exports of small bakes of the Cornell boxes and the shared scenes
# (`bundlebake export`) must pass the Khronos glTF-Validator with 0 errors
# (tests/validator/validate.js; scripts/install-deps.sh installs the npm
# package). A missing node or validator is a failure, not a skip.
# Usage: export_validate.sh BUNDLEBAKE_CLI SOURCE_DIR
set -u
cli=$1 src=$2
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
status=0

if ! command -v node >/dev/null 2>&1; then
    echo "FAIL: node is not installed (scripts/install-deps.sh)"; exit 1
fi
if [ ! -f "$src/tests/validator/node_modules/gltf-validator/package.json" ]; then
    echo "FAIL: gltf-validator is not installed in tests/validator (scripts/install-deps.sh)"; exit 1
fi

# name, scene, bake flags
export_one() {
    name=$1 scene=$2; shift 2
    start=$(date +%s)
    if ! "$cli" -q bake "$scene" -o "$tmp/$name" --no-progress --no-preview "$@" 2>"$tmp/$name.err"; then
        echo "FAIL: bake of $name:"; cat "$tmp/$name.err"; status=1; return
    fi
    if ! "$cli" -q export "$scene" "$tmp/$name" -o "$tmp/$name.glb" 2>"$tmp/$name.err"; then
        echo "FAIL: export of $name:"; cat "$tmp/$name.err"; status=1; return
    fi
    echo "$name: baked and exported in $(( $(date +%s) - start )) s ($*), $(wc -c <"$tmp/$name.glb") bytes"
    files="$files $tmp/$name.glb"
}

# whole-texel bakes (--supersample 1): the export, not the bake, is tested here, and
# the light maps' layout is the same either way
files=""
export_one cornell_box "$src/assets/cornell_box/cornell_box.gltf" --directions 16 --resolution 128 --supersample 1
export_one cornell_box_shared "$src/assets/shared/cornell_box/CornellBox.glb" --directions 16 --resolution 256 --supersample 1
export_one mixed_lighting "$src/assets/shared/mixed_lighting/MixedLightingExample.gltf" --directions 16 --resolution 256 --supersample 1
export_one living_room "$src/assets/shared/living_room/living_room.glb" --resolution 512 --directions 16 --sky 1,1,1 --supersample 1
export_one zdm2 "$src/assets/shared/zdm2/zdm2.glb" --resolution 512 --directions 16 --sky 1,1,1 --supersample 1

# shellcheck disable=SC2086
if ! node "$src/tests/validator/validate.js" $files; then
    echo "FAIL: the validator reported errors"; status=1
fi
[ "$status" -eq 0 ] && echo "PASS: every export has 0 validator errors"
exit $status
