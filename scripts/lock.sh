#!/usr/bin/env bash
# Renew uv.lock to the newest versions pyproject.toml allows, rebuild .venv from it, and run the
# whole suite against it. Commit uv.lock when the suite passes. Arguments go to `uv lock`
# (e.g. `--upgrade-package trimesh` to move one package only; the default moves all).
set -euo pipefail
cd "$(dirname "$0")/.."
export UV_SYSTEM_CERTS=1  # the system's certificate store, as scripts/setup.sh says
UV_VERSION=$(sed -n 's/^UV_VERSION=//p' scripts/setup.sh)
uv="${XDG_CACHE_HOME:-$HOME/.cache}/mpc/uv-$UV_VERSION/bin/uv"
[ -x "$uv" ] || bash scripts/setup.sh --dev
UV_PYTHON_DOWNLOADS=never "$uv" lock "${@:---upgrade}"
bash scripts/test.sh
