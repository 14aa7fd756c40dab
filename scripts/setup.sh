#!/usr/bin/env bash
# Install everything mpc and its tests need on a fresh Debian machine:
# Debian's check_urdf (liburdfdom-tools), sdformat 12 tools (`ign sdf`), Graphviz's `dot`
# and poppler's `pdftoppm`, git-lfs (deployments that track meshes with LFS), then mpc
# itself with its dev extra (pytest, hypothesis, Pinocchio, MuJoCo, example-robot-data,
# ruff), editable.
set -euo pipefail
cd "$(dirname "$0")/.."
sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
if ! command -v check_urdf >/dev/null || ! command -v ign >/dev/null || ! command -v dot >/dev/null \
    || ! command -v pdftoppm >/dev/null || ! command -v git-lfs >/dev/null; then
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq liburdfdom-tools ignition-tools \
    libsdformat12-12 sdformat-sdf libsdformat-dev graphviz poppler-utils git-lfs >/dev/null
fi
python3 -m pip install -q --disable-pip-version-check -e '.[dev]'
