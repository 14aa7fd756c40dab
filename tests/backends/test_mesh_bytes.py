"""Computed meshes are byte for byte what mpc wrote before the mesh work of issue 19.

Real example-robot-data meshes: the UR5's first three links (DAE visuals, STL collisions)
and a mirrored copy of them (every mesh reflected), written as STL, OBJ and bobj. The digests of every
output file were recorded by mpc as it was before the mesh cache kept a normalized form
(`MPC_UPDATE_GOLDEN=1` records them again). Cold (an empty cache) and warm (the filled one)
builds must both give them.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import pytest

from mpc.core.diagnostics import Sink
from tests.conftest import ERD, compile_file

DIGESTS = Path(__file__).parent.parent / "fixtures/mesh_output_digests.json"
UPDATE = os.environ.get("MPC_UPDATE_GOLDEN") == "1"

DEFINITION = f"""model:
  robotname: arms
  modelname: arms
  input_models:
    ur5: {{basefile: "{ERD / 'ur_description/urdf/ur5_robot.urdf'}"}}
  assemble:
    model: ur5
    remove_beyond: upper_arm_link
    children:
      - model: ur5
        remove_beyond: upper_arm_link
        mirror: {{name_replacements: {{"^(.*)$": "mirrored_\\\\1"}}}}
        joint: {{parent: base_link, name: to_mirrored, xyz: [0, 0.5, 0]}}
  export_config:
    - {{type: urdf, mesh_format: stl}}
    - {{type: urdf, mesh_format: obj, filename_suffix: _obj}}
    - {{type: urdf, mesh_format: bobj, filename_suffix: _bobj}}
"""


def digests(out: Path) -> dict[str, str]:
    return {str(p.relative_to(out)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(out.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def builds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, str]]:
    """The digests of a cold and a warm build (one cache of their own)."""
    tmp = tmp_path_factory.mktemp("mesh-bytes")
    spec = tmp / "arms.yml"
    spec.write_text(DEFINITION)
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("MPC_CACHE_DIR", str(tmp / "cache"))
        found = {}
        for label in ("cold", "warm"):
            sink = Sink()
            result = compile_file(spec, tmp / label, sink)
            assert result.out is not None, [d.message for d in sink.diagnostics]
            assert not sink.diagnostics, [d.message for d in sink.diagnostics]
            found[label] = digests(result.out)
    if UPDATE:
        DIGESTS.write_text(json.dumps(found["cold"], indent=1, sort_keys=True) + "\n")
    return found


@pytest.mark.parametrize("label", ["cold", "warm"])
def test_outputs_are_byte_for_byte_as_before(builds: dict[str, dict[str, str]], label: str) -> None:
    expected = json.loads(DIGESTS.read_text())
    assert len([name for name in expected if name.startswith("meshes/")]) == 3 * 4 * 3
    assert builds[label] == expected
