#!/usr/bin/env bash
# Run mpc's tests on every core. The first run installs what the tests need and mpc does not
# (scripts/setup.sh --dev: the dev extra, check_urdf, ign sdf, Chromium, Neovim, the npm tools);
# later runs only bring .venv to uv.lock. Arguments go to pytest (e.g. tests/core).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --dev
exec .venv/bin/python -m pytest -n auto -q "$@"
