#!/usr/bin/env bash
# Set up bt-humanoid on a fresh Debian machine: system libraries for off-screen
# rendering (Mesa EGL) and speech (espeak-ng), then a virtual environment in .venv with the package,
# its test tools and every Python dependency. Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."

debian_packages=(libegl1 libegl-mesa0 libgl1-mesa-dri espeak-ng)
missing=()
for package in "${debian_packages[@]}"; do
  dpkg -s "$package" >/dev/null 2>&1 || missing+=("$package")
done
if [ ${#missing[@]} -gt 0 ] && command -v apt-get >/dev/null; then
  echo "installing Debian packages: ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${missing[@]}" >/dev/null
fi

python=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  "$python" -m venv .venv
fi
.venv/bin/python -m pip install -q --upgrade pip
# torch first, pinned: the CPU build (anything that lets pip choose pulls a newer one with GBs of CUDA)
.venv/bin/python -m pip install -q "torch==2.13.0"
.venv/bin/python -m pip install -q -e ".[test]"
echo "bt-humanoid is set up in .venv"
