#!/usr/bin/env bash
# Install everything mpc and its tests need on a fresh Debian machine:
# Debian's check_urdf (liburdfdom-tools), then mpc itself with its dev extra
# (pytest, hypothesis, Pinocchio, example-robot-data, ruff), editable.
set -euo pipefail
cd "$(dirname "$0")/.."
sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
if ! command -v check_urdf >/dev/null; then
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq liburdfdom-tools >/dev/null
fi
python3 -m pip install -q --disable-pip-version-check -e '.[dev]'
