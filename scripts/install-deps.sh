#!/bin/sh
# Installs the Debian 12 packages bundlebake builds, tests and benches with.
# Idempotent and non-interactive; run as root. Only calls apt-get when
# something is missing, so a second run costs a dpkg query.
set -eu

PACKAGES="
g++ cmake make pkg-config python3 python3-glad
libegl-dev libegl-mesa0 libgl1-mesa-dri libgl-dev libosmesa6-dev
libglm-dev libopenexr-dev zlib1g-dev libimath-dev libtinygltf-dev libstb-dev
nlohmann-json3-dev libcli11-dev libgtest-dev libembree-dev
libglfw3-dev libimgui-dev xvfb xauth python3-matplotlib openimageio-tools libeigen3-dev
clang libclang-rt-14-dev
libopenmpi-dev openmpi-bin
"

missing=""
for p in $PACKAGES; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done

if [ -n "$missing" ]; then
    echo "install-deps: installing:$missing"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -q
    # shellcheck disable=SC2086
    apt-get install -y -q --no-install-recommends $missing
else
    echo "install-deps: all packages present"
fi

# The Khronos glTF-Validator for the export tests (tests/validator, npm
# package gltf-validator at the version pinned in its package.json), unless
# it is there. npm comes with Debian's nodejs and npm packages when absent.
VALIDATOR_DIR="$(cd "$(dirname "$0")/.." && pwd)/tests/validator"
if [ ! -f "$VALIDATOR_DIR/node_modules/gltf-validator/package.json" ]; then
    if ! command -v npm >/dev/null 2>&1; then
        echo "install-deps: installing: nodejs npm"
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -q
        apt-get install -y -q --no-install-recommends nodejs npm
    fi
    echo "install-deps: installing gltf-validator into tests/validator"
    (cd "$VALIDATOR_DIR" && npm ci --no-audit --no-fund --loglevel=error)
fi
