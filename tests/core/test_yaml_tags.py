"""The implicit tags of YAML scalars (core/yaml_source.py, kept per text and quoting): the same
text reads as a number, a boolean or null when plain and as a string when quoted, in one
document and from one document to the next, with libyaml and with the Python composer."""

from __future__ import annotations

import pytest

from mpc.core import yaml_source
from mpc.core.diagnostics import Sink

TEXT = """plain: [1, 1.5, true, null, ~, '1', "1.5", 'true', 'null', "~", 0x1f, '0x1f', 1e3, "1e3"]
again: [1, '1', true, 'true']
"""


@pytest.mark.parametrize("fast", [True, False])
def test_quoted_and_plain_scalars(fast: bool) -> None:
    for _ in range(2):  # the second time from the kept tags
        doc = yaml_source.loads(TEXT, "t.yml", Sink(), fast=fast)
        assert doc is not None
        assert doc.data == {
            "plain": [1, 1.5, True, None, None, "1", "1.5", "true", "null", "~", 31, "0x1f", 1000.0, "1e3"],
            "again": [1, "1", True, "true"],
        }
