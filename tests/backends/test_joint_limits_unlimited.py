"""joint_limits writes a continuous joint as unlimited the way ROCK reads it (issue 29, point 6):
min and max position `.nan` (base::unset), not 0..0, which reads as a locked joint."""

from __future__ import annotations

import math
from pathlib import Path

import yaml
from lxml import etree

from tests.conftest import ERD, Diags, compile_file, write

KINOVA = ERD / "kinova_description/robots/kinova.urdf"


def test_continuous_joints_are_unlimited_others_keep_their_limits(tmp_path: Path, diags: Diags) -> None:
    spec = write(tmp_path / "m.yml", f"""
        model:
          robotname: kinova
          modelname: kinova_model
          input_models: {{base: {{basefile: "{KINOVA}"}}}}
          assemble: {{model: base}}
          export_config:
            - {{type: joint_limits, joints: ALL}}
        """)
    out = compile_file(spec, tmp_path / "out", diags).out
    assert out is not None
    text = (out / "joint_limits.yml").read_text()
    limits = yaml.safe_load(text)["limits"]
    source = {j.get("name"): j for j in etree.parse(str(KINOVA)).getroot().findall("joint")}
    continuous = [n for n, j in source.items() if j.get("type") == "continuous"]
    assert len(continuous) == 3 and set(continuous) <= set(limits["names"])
    for name, element in zip(limits["names"], limits["elements"], strict=True):
        low, high = element["min"]["position"], element["max"]["position"]
        if name in continuous:
            assert math.isnan(low) and math.isnan(high), name
        else:
            limit = source[name].find("limit")
            assert (low, high) == (float(limit.get("lower")), float(limit.get("upper"))), name
    assert text.count("position: .nan") == 2 * len(continuous)
