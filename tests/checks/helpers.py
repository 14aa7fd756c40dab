"""Helpers of the model-test tests: definitions with a `test` section, real models edited
in place (lxml), compiling and running the tests."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from mpc.checks import Protocol, run_model_tests
from mpc.compiler.driver import Options, Result, compile_model
from mpc.core.diagnostics import Sink
from tests.conftest import definition as model_definition
from tests.conftest import write

EVERY_TEST = """\
      - process_double_check
      - load_in_pybullet
      - compare_link_masses
      - compare_link_transformations
      - compare_amount_joints
      - hyrodynChecks:
          - load_in_hyrodyn
          - compare_masses
          - compare_com
          - compare_torques
          - compare_link_positions
"""


def definition(basefile: Path | str, name: str, tests: str, compare: str = "", extra: str = "",
               exports: str = "") -> str:
    """A model definition of one input model with a test section.

    tests: the lines of `tests:` (indented by 6); compare: lines of compare_model (by 6);
    extra: further model sections (indented by 2); exports: further export_config entries."""
    text = model_definition(basefile, robotname=name) + exports + extra + "  test:\n"
    if compare:
        text += "    compare_model:\n" + compare
    return text + "    tests:\n" + tests


def compile_ok(path: Path, out: Path) -> Result:
    sink = Sink()
    result = compile_model(path, sink, Options(out=out))
    errors = [f"{d.span}: {d.code} {d.message}" for d in sink.diagnostics if d.severity.name == "ERROR"]
    assert result.out is not None, errors
    return result


def run(path: Path, out: Path, workdir: Path, sink: Sink | None = None) -> Protocol:
    """Compile the definition at `path` into `out` and run its tests."""
    result = compile_ok(path, out)
    assert result.program is not None and result.robot is not None
    return run_model_tests(result.program, out, sink or Sink(), workdir=workdir, robot=result.robot)


def statuses(protocol: Protocol) -> dict[str, str]:
    return {r.name: r.status for r in protocol.results}


def failing(protocol: Protocol) -> set[str]:
    return {r.name for r in protocol.results if r.status in ("failed", "waived")}


def result(protocol: Protocol, name: str):
    return next(r for r in protocol.results if r.name == name)


def edited_urdf(source: Path, target: Path, edit) -> Path:
    """A copy of a real URDF at `target`, changed by `edit(root)`; package:// meshes still resolve."""
    tree = etree.parse(str(source), etree.XMLParser(remove_comments=False, resolve_entities=False))
    edit(tree.getroot())
    target.parent.mkdir(parents=True, exist_ok=True)
    tree.write(str(target), xml_declaration=True, encoding="utf-8")
    return target


def link_el(root: etree._Element, name: str) -> etree._Element:
    return root.find(f"link[@name='{name}']")


def joint_el(root: etree._Element, name: str) -> etree._Element:
    return root.find(f"joint[@name='{name}']")


def floats(text: str) -> list[float]:
    return [float(x) for x in text.split()]


def fmt(values: list[float]) -> str:
    return " ".join(repr(v) for v in values)


__all__ = [
    "EVERY_TEST",
    "compile_ok",
    "definition",
    "edited_urdf",
    "failing",
    "floats",
    "fmt",
    "joint_el",
    "link_el",
    "result",
    "run",
    "statuses",
    "write",
]
