"""The kinematic-tree PDF and the ROCK joint-limits files, from the command line's path."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import yaml

from tests.conftest import ERD, Diags, compile_file, write
from tests.fixtures import arm

SM = """
  submechanisms:
    - name: arm_chain
      type: serial
      jointnames_spanningtree: [shoulder, elbow]
      jointnames_active: [elbow]
      jointnames_independent: [shoulder]
"""


def test_joint_limits_all_active_independent(tmp_path: Path) -> None:
    arm(tmp_path)
    spec = write(tmp_path / "m.yml", """
model:
  robotname: arm
  modelname: arm-model
  input_models: {arm: {basefile: arm.urdf}}
  assemble: {model: arm}
""" + SM + """
  export_config:
    - {type: joint_limits, joints: ALL, file_name: all.yml}
    - {type: joint_limits, joints: ACTIVE, file_name: active.yml}
    - {type: joint_limits, joints: INDEPENDENT, file_name: independent.yml}
    - {type: joint_limits, joints: [elbow], file_name: listed.yml}
""")
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    shoulder = {"max": {"position": 1.5, "speed": 2.0, "effort": 10.0}, "min": {"position": -1.5}}
    elbow = {"max": {"position": 2.0, "speed": 3.0, "effort": 5.0}, "min": {"position": -2.0}}
    expected = {"all": (["shoulder", "elbow"], [shoulder, elbow]), "active": (["elbow"], [elbow]),
                "independent": (["shoulder"], [shoulder]), "listed": (["elbow"], [elbow])}
    for name, (names, elements) in expected.items():
        data = yaml.safe_load((out / f"{name}.yml").read_text())
        assert data == {"limits": {"names": names, "elements": elements}}, name
    # Block style, keys sorted, as Phobos's YAML writer wrote it (not JSON in a .yml file).
    assert (out / "listed.yml").read_text() == (
        "limits:\n  elements:\n  - max:\n      effort: 5.0\n      position: 2.0\n      speed: 3.0\n"
        "    min:\n      position: -2.0\n  names:\n  - elbow\n")


def test_kinematic_tree_pdf(tmp_path: Path) -> None:
    source = ERD / "talos_data/robots/talos_left_arm.urdf"
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: arm
          modelname: arm-graph
          input_models: {{arm: {{basefile: "{source}"}}}}
          assemble: {{model: arm}}
          submechanisms:
            - {{name: wrist, type: serial, jointnames_spanningtree: [arm_left_6_joint, arm_left_7_joint]}}
          export_config: [{{type: pdf}}]
        """)
    out = compile_file(spec, tmp_path / "out", Diags()).out
    assert out is not None
    gv = (out / "arm.pdf.gv").read_text()
    from mpc.backends import urdf
    from mpc.core.diagnostics import Sink

    robot = urdf.read(source, Sink())
    assert robot is not None
    assert all(f'"link:{name}" [shape=box' in gv for name in robot.links)
    assert all(f'"joint:{name}" [shape=ellipse' in gv for name in robot.joints)
    assert gv.count('fillcolor="lightblue"') == 2  # the wrist submechanism's joints
    png = tmp_path / "page"
    subprocess.run([shutil.which("pdftoppm") or "pdftoppm", "-png", "-r", "30", "-f", "1", "-l", "1",
                    str(out / "arm.pdf"), str(png)], check=True)
    pages = list(tmp_path.glob("page*.png"))
    assert len(pages) == 1 and pages[0].stat().st_size > 1000
