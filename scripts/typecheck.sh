#!/usr/bin/env bash
# Type-check mpc's own code with basedpyright (the settings are [tool.basedpyright] in
# pyproject.toml), against the baseline .basedpyright/baseline.json, which may only shrink:
#  - an error or warning that the baseline does not list fails the check;
#  - a listed one that is gone fails it too: basedpyright then removes it from the baseline,
#    and the shrunk file is to be committed.
# `bash scripts/typecheck.sh --writebaseline` records the errors as they are first (only to
# accept an error on purpose). Run by .ci/run after the suite; needs the .venv of
# `scripts/setup.sh --dev`.
set -euo pipefail
cd "$(dirname "$0")/.."
baseline=.basedpyright/baseline.json
if [ "${1:-}" = --writebaseline ]; then
  .venv/bin/basedpyright --writebaseline >/dev/null || true  # it exits 1 on the errors it records
fi
before=$(mktemp)
trap 'rm -f "$before"' EXIT
cp "$baseline" "$before"
# auto, not lock: where CI is set, basedpyright would lock the baseline and exit 3 on a fixed error
.venv/bin/basedpyright --warnings --baselinemode=auto
if ! cmp -s "$baseline" "$before"; then
  echo "typecheck: errors of the baseline are fixed; commit the shrunk $baseline" >&2
  exit 1
fi
