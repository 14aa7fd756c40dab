#!/usr/bin/env bash
# What a user who installs mpc's wheel gets: build the wheel, install it without extras into a
# fresh virtual environment (with example-robot-data, the robots' package, beside it), and
# compile ur5, tiago_dual and anymal from outside the repository into STL meshes, each of which
# must have triangles. Run by .ci/run after the suite.
set -euo pipefail
cd "$(dirname "$0")/.."
export UV_SYSTEM_CERTS=1  # the system's certificate store, as scripts/setup.sh says
repo=$(pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
UV_VERSION=$(sed -n 's/^UV_VERSION=//p' scripts/setup.sh)
uv="${XDG_CACHE_HOME:-$HOME/.cache}/mpc/uv-$UV_VERSION/bin/uv"
export UV_PYTHON_DOWNLOADS=never
# Built from a copy of the tracked files: setuptools leaves build/ behind in the tree it builds.
mkdir "$work/src"
git ls-files -z | xargs -0 cp --parents -t "$work/src"
"$uv" build --wheel --out-dir "$work/dist" --quiet "$work/src"
"$uv" venv --quiet --python "${PYTHON:-python3}" "$work/venv"
# The wheel's dependencies at the versions of the lock, so that a user's install and CI agree.
"$uv" export --quiet --frozen --no-dev --no-emit-project --no-hashes -o "$work/constraints.txt" --project "$repo"
VIRTUAL_ENV="$work/venv" "$uv" pip install --quiet -c "$work/constraints.txt" "$work"/dist/*.whl \
  "example-robot-data==$(sed -n '/^name = "example-robot-data"$/{n;s/^version = "\(.*\)"$/\1/p}' uv.lock)"
cd "$work"
export MPC_CACHE_DIR="$work/cache"  # cold: no mesh computed on this machine before counts
erd=$("$work/venv/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")/cmeel.prefix/share/example-robot-data/robots
for robot in ur_description/urdf/ur5_robot.urdf tiago_description/robots/tiago_dual.urdf \
             anymal_b_simple_description/robots/anymal.urdf; do
  name=$(basename "$robot" | sed 's/\..*//')
  cat > "$name.yml" <<YAML
model:
  robotname: $name
  modelname: $name-model
  input_models: {robot: {basefile: "$erd/$robot"}}
  assemble: {model: robot}
  export_config: [{type: urdf, mesh_format: stl}]
YAML
  "$work/venv/bin/mpc" compile "$name.yml" -o "out/$name"
done
"$work/venv/bin/python" - <<'PY'
import pathlib, struct
stls = sorted(pathlib.Path("out").rglob("*.stl"))
empty = [str(p) for p in stls if struct.unpack("<I", p.read_bytes()[80:84])[0] == 0]
assert stls and not empty, f"STL meshes without triangles: {empty}"
print(f"check_wheel: {len(stls)} STL meshes of ur5, tiago_dual and anymal, all with triangles")
PY
