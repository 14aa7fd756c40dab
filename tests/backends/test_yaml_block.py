"""SMURF and joint-limit YAML (backends/smurf.py `dumps`): the block writer for plain data and
libyaml write exactly PyYAML's bytes, whatever the data (names, quoted text, numbers, nesting)."""

from __future__ import annotations

import math

import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from mpc.backends import smurf
from mpc.backends.yaml_block import block_yaml

WORDS = ["x", "l1", "package://a/b.dae", "a:b", "a: b", "ab:", "a #b", "a b c", "yes", "No", "ON",
         "null", "y", "~", "", " a", "1.5", "0x1f", "-", ".inf", "é", "日本", "\x85", "😀", "a\nb",
         "'q'", '"q"', "a" * 61, "a" * 130, "../urdf/a.urdf", "../../a b", "../", "../.inf", "../a: b",
         ".../a", "../1"]
TEXT = st.one_of(st.sampled_from(WORDS), st.text(max_size=12))
SCALARS = st.one_of(st.none(), st.booleans(), st.integers(), TEXT,
                    st.floats(allow_nan=True, allow_infinity=True))
DATA = st.recursive(SCALARS, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                     st.dictionaries(TEXT, inner, max_size=4)),
                    max_leaves=20)


def pyyaml(data: object) -> str:
    return yaml.dump(smurf.plain(data), Dumper=smurf._dumpers()[0], default_flow_style=False, sort_keys=True,
                     allow_unicode=True, width=1 << 16)


@settings(max_examples=30)  # each example is cheap, generating it is not
@given(st.dictionaries(TEXT, DATA, min_size=1, max_size=4))
def test_dumps_writes_pyyamls_bytes(data: dict[str, object]) -> None:
    assert smurf.dumps(data) == pyyaml(data)


def test_the_block_writer_takes_a_smurfs_plain_data() -> None:
    data = {"joints": [{"name": "j1", "type": "revolute", "limits": {"lower": -1.5, "upper": 2.0}},
                       {"name": "j2", "axis": [0.0, 1e-05, math.inf], "parents": [], "x": {}}],
            "links": [[1, 2], [{"a": None, "b": True}]], "file": "package://robot/meshes/a.stl",
            "description": "", "files": ["../urdf/arm.urdf"]}  # a SMURF's
    assert block_yaml(data) == pyyaml(data) == smurf.dumps(data)
    assert block_yaml({"name": "a: b"}) is None  # left to PyYAML, which quotes it
