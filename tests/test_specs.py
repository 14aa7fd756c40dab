"""specs/ stays true: its examples check, lower and compile as their pages say.

An example is a ```yaml block whose first line is `# example: NAME` (NAME unique,
snake_case). Comment lines right after it mark it:
- `# compile: later`: `mpc check` accepts it with W0202 warnings only (at least one),
  and `mpc compile` does not build it yet;
- otherwise `mpc check` reports nothing, and `mpc compile` builds it, with no
  diagnostic but W0500 (what the URDF cannot hold) and W0520 (KCCD's tools missing);
- `# kind: pipeline`: a pipeline file; it is only checked.

Each example runs in a copy of specs/examples/ (the small models it names) as
`NAME.yml`. Its IR (`mpc compile --emit ir`, with the copy's folder shown as
`<specs>`) must equal `specs/examples/NAME.ir`; `MPC_UPDATE_GOLDEN=1` rewrites the
golden files instead, and the test then fails so that such a run never passes.
"""

from __future__ import annotations

import os
import re
import shutil
from dataclasses import dataclass
from pathlib import Path

import pytest

from mpc.cli.check import check_file
from mpc.compiler.driver import Options, compile_model
from mpc.compiler.front_end import load_program
from mpc.core import render
from mpc.core.diagnostics import Severity, Sink
from mpc.ir.text import dump
from tests.conftest import ERD_PACKAGE
from tests.fixtures import ARM_URDF, tetra_stl

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"
EXAMPLES = SPECS / "examples"
UPDATE = os.environ.get("MPC_UPDATE_GOLDEN") == "1"
MARKS = {"compile": {"later"}, "kind": {"model", "pipeline"}}
# Pages that describe mpc rather than a section of the language need no example.
NO_EXAMPLE = {"README.md", "diagnostics.md", "diff.md", "files.md", "layers.md", "lsp.md", "passes.md",
              "urdf.md"}


@dataclass(frozen=True)
class Example:
    """One runnable example: where it is, its name, its YAML and its marks."""

    page: str
    name: str
    text: str
    marks: dict[str, str]

    @property
    def later(self) -> bool:
        return self.marks.get("compile") == "later"

    @property
    def pipeline(self) -> bool:
        return self.marks.get("kind") == "pipeline"

    @property
    def golden(self) -> Path:
        return EXAMPLES / f"{self.name}.ir"


def _examples() -> list[Example]:
    found = []
    for page in sorted(SPECS.glob("*.md")):
        for block in re.findall(r"```yaml\n(.*?)```", page.read_text(), re.DOTALL):
            lines = block.split("\n")
            m = re.fullmatch(r"# example: (\S+)", lines[0])
            if not m:
                continue
            marks = {}
            for line in lines[1:]:
                mark = re.fullmatch(r"# (\w+): (\S+)", line)
                if not mark:
                    break
                marks[mark.group(1)] = mark.group(2)
            found.append(Example(page.name, m.group(1), block, marks))
    return found


EXAMPLES_FOUND = _examples()
IDS = [f"{e.page}:{e.name}" for e in EXAMPLES_FOUND]


def _summary(sink: Sink) -> str:
    return render.human(sink.diagnostics) if sink.diagnostics else "none"


def _shown(text: str, folder: Path) -> str:
    """IR text without what depends on the machine: the example folder, installed packages."""
    text = text.replace(str(folder), "<specs>")
    if ERD_PACKAGE is not None:
        text = text.replace(str(ERD_PACKAGE.resolve()), "<example-robot-data>")
    return text


def test_there_are_examples() -> None:
    assert len(EXAMPLES_FOUND) >= 1


def test_example_names_are_unique_and_marks_known() -> None:
    seen: dict[str, str] = {}
    for e in EXAMPLES_FOUND:
        assert re.fullmatch(r"[a-z][a-z0-9_]*", e.name), \
            f"{e.page}: example name '{e.name}' is not snake_case"
        assert e.name not in seen, f"example '{e.name}' is in {seen[e.name]} and in {e.page}"
        seen[e.name] = e.page
        for key, value in e.marks.items():
            assert value in MARKS.get(key, set()), \
                f"{e.page}: example '{e.name}' has an unknown mark '# {key}: {value}' (known: {MARKS})"


def test_every_page_is_indexed_and_has_an_example() -> None:
    index = (SPECS / "README.md").read_text()
    with_examples = {e.page for e in EXAMPLES_FOUND}
    for page in sorted(SPECS.glob("*.md")):
        if page.name == "README.md":
            continue
        assert f"]({page.name})" in index, f"specs/README.md does not list {page.name}"
        if page.name not in NO_EXAMPLE:
            assert page.name in with_examples, f"specs/{page.name} has no runnable example"


def test_every_golden_file_belongs_to_an_example() -> None:
    names = {e.name for e in EXAMPLES_FOUND if not e.pipeline}
    stale = sorted(p.name for p in EXAMPLES.glob("*.ir") if p.stem not in names)
    assert not stale, f"golden files without an example (delete them): {stale}"


def test_example_models_are_the_test_fixtures() -> None:
    """specs/examples/arm.urdf and its mesh are the arm the other tests use."""
    assert (EXAMPLES / "arm.urdf").read_text() == ARM_URDF


def test_example_mesh_is_the_test_fixture(tmp_path: Path) -> None:
    assert (EXAMPLES / "meshes" / "tetra.stl").read_bytes() == tetra_stl(tmp_path / "t.stl").read_bytes()


@pytest.mark.parametrize("example", EXAMPLES_FOUND, ids=IDS)
def test_example(example: Example, tmp_path: Path) -> None:
    folder = tmp_path.resolve() / "specs"
    shutil.copytree(EXAMPLES, folder, ignore=shutil.ignore_patterns("*.ir"))
    path = folder / f"{example.name}.yml"
    assert not path.exists(), f"example '{example.name}' has the name of a file in specs/examples/"
    path.write_text(example.text)

    # mpc check: no errors; W0202 (not built yet) only where the page says so.
    sink = Sink()
    check_file(path, sink, Options())
    codes = [(d.severity, d.code) for d in sink.diagnostics]
    where = f"{example.page}: example '{example.name}'"
    if example.later:
        assert codes and all(c == (Severity.WARNING, "W0202") for c in codes), \
            f"{where} is marked '# compile: later', so `mpc check` must give W0202 warnings " \
            f"and nothing else (remove the mark once it compiles); got: {_summary(sink)}"
    else:
        assert not codes, f"{where}: `mpc check` reported: {_summary(sink)}"
    if example.pipeline:
        return

    # The IR, against its golden file.
    sink = Sink()
    program = load_program(path, sink, Options(), Severity.WARNING if example.later else Severity.ERROR)
    assert program is not None, f"{where}: no IR: {_summary(sink)}"
    text = _shown(dump(program), folder)
    if UPDATE:
        example.golden.write_text(text)
        pytest.fail(f"updated {example.golden.relative_to(ROOT)}; run again without MPC_UPDATE_GOLDEN")
    assert example.golden.exists(), f"{where}: no golden file {example.golden.relative_to(ROOT)}; " \
                                    "write it with MPC_UPDATE_GOLDEN=1"
    assert text == example.golden.read_text(), f"{where}: the IR differs from {example.golden.name}"

    # mpc compile builds what is not marked `later`. The warnings allowed: W0500, the URDF
    # leaves out what only SMURF can hold (sensors, poses, annotations, …); W0520, KCCD's
    # tools (packaged nowhere) are not installed.
    if not example.later:
        sink = Sink()
        result = compile_model(path, sink, Options(out=tmp_path / "out"))
        codes = {d.code for d in sink.diagnostics}
        assert result.out is not None and codes <= {"W0500", "W0520"}, f"{where}: compile: {_summary(sink)}"


def test_every_code_is_documented() -> None:
    used = set()
    for folder in ("core", "ir", "backends", "compiler", "checks", "deploy", "pipeline", "cli"):
        for path in (ROOT / folder).rglob("*.py"):
            used |= set(re.findall(r'"([EW]\d{4})"', path.read_text()))
    documented = set(re.findall(r"^\| ([EW]\d{4}) \|", (SPECS / "diagnostics.md").read_text(), re.M))
    assert used == documented
