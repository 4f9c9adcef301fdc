#!/usr/bin/env bash
# Installs what alight needs on a Debian machine, skipping what is already there:
#   Debian: Mesa's EGL and software OpenGL (headless renders), Xvfb and XTest (the editor's window tests);
#     xdotool (real X key events for the editor's own loop: tests/test_editor_ui_widgets.py);
#   Python: a virtual environment in .venv with alight installed from this checkout (not editable).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(libegl1 libegl-mesa0 libgl1-mesa-dri libgbm1 libgl1 xvfb xauth libxtst6 xdotool)
missing=()
for pkg in "${packages[@]}"; do
  dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${missing[*]}"
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

python=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv"
  "$python" -m venv .venv
fi
# A real (non-editable) install: the tests run against what users get. setuptools builds in
# build/, where a module deleted from app/ would live on and slip into the wheel: start clean.
rm -rf build
# pip's own status decides (a filter in a pipeline would hide a failed install); its noise about
# this machine's unused local package folders is dropped from what is shown.
log=$(mktemp)
if ! .venv/bin/python -m pip install --quiet --disable-pip-version-check ".[test]" >"$log" 2>&1; then
  grep -v "is ignored: it is neither a file nor a directory" "$log" >&2
  rm -f "$log"
  echo "setup: pip install failed" >&2
  exit 1
fi
rm -f "$log"

# The Khronos glTF validator (npm), for the tests of `alight export`, and the optimisers whose
# files the compressed-glTF tests read (gltfpack, @gltf-transform/cli); skipped without node.
if command -v npm >/dev/null 2>&1 && [ ! -d tools/node/node_modules/gltf-validator ]; then
  echo "setup: installing gltf-validator (npm) into tools/node"
  npm install --silent --no-save --prefix tools/node gltf-validator >/dev/null
fi
if command -v npm >/dev/null 2>&1 && { [ ! -d tools/node/node_modules/gltfpack ] || [ ! -d tools/node/node_modules/@gltf-transform/cli ]; }; then
  echo "setup: installing gltfpack and @gltf-transform/cli (npm) into tools/node"
  npm install --silent --no-save --prefix tools/node gltf-validator gltfpack @gltf-transform/cli >/dev/null
fi
