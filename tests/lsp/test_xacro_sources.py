"""lsp/xacro_sources.py, go to definition's search when a xacro model cannot be expanded again
(backends/xacro_origins.py is what answers otherwise): the element in the xacro file or a file
it includes, a `${…}` template when exactly one can give the name."""

from __future__ import annotations

from pathlib import Path

from mpc.core.packages import PackageResolver
from mpc.lsp.xacro_sources import find_element
from tests.lsp.test_names_in_context import BODY, LEG, TOP


def test_the_search_of_included_files(tmp_path: Path) -> None:
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "body.xacro").write_text(BODY, encoding="utf-8")
    package = tmp_path / "bot_parts"
    (package / "urdf").mkdir(parents=True)
    (package / "urdf" / "leg.xacro").write_text(LEG, encoding="utf-8")
    (tmp_path / "bot.urdf.xacro").write_text(TOP, encoding="utf-8")
    resolver = PackageResolver(package_map={"bot_parts": package})
    top, leg = tmp_path / "bot.urdf.xacro", str((package / "urdf" / "leg.xacro").resolve())

    def found(kind: str, name: str) -> tuple[str, int, int] | None:
        span = find_element(top, kind, name, resolver)
        return None if span is None else (span.file, span.line, span.col)

    assert found("link", "torso") == (str((tmp_path / "parts" / "body.xacro").resolve()), 4, 5)
    assert found("joint", "left_hip") == (leg, 4, 5)  # the one joint template: "${side}_hip"
    assert found("link", "left_thigh") is None  # "${side}_thigh" and the spare "${part}_thigh"
    assert found("link", "arm") is None
    (package / "urdf" / "leg.xacro").write_text(LEG.replace('"${part}_thigh"', '"${part}_shin"'),
                                                encoding="utf-8")
    assert found("link", "left_thigh") == (leg, 10, 5)
