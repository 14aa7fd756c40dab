"""The project's documentation stands alone: README.md and the pages of specs/ (and
bench/README.md) link only to files of the repository, which exist, and name no path out of
it. (A relative path written as text, such as `../meshes/stl` in an output, may name a file
that is not in the repository, unless it names a page (`.md`); it must not lead out of it.)"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = sorted([ROOT / "README.md", ROOT / "bench/README.md", *(ROOT / "specs").rglob("*.md")])
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")  # [text](target)
RELATIVE = re.compile(r"(?<![\w./-])(\.\.?/[\w./-]*\w)")  # ../x/y.md or ./x, written as text
OUTSIDE = re.compile(r"(?<![\w.])/work/|shared/reference")  # the machine's folders that a clone lacks


def _problems(page: Path) -> list[str]:
    text = page.read_text(encoding="utf-8")
    links = [t for t in LINK.findall(text) if not re.match(r"[a-z]+:", t) and not t.startswith("#")]
    out = []
    for target in [*links, *RELATIVE.findall(LINK.sub("", text))]:
        path = (page.parent / target.split("#")[0]).resolve()
        if not path.is_relative_to(ROOT):
            out.append(f"{target}: outside the repository")
        elif (target in links or target.endswith(".md")) and not path.exists():  # a page it names
            out.append(f"{target}: no such file")
    out += [f"names {m.group()!r}" for m in OUTSIDE.finditer(text)]
    return out


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_the_documentation_links_only_files_of_the_repository(page: Path) -> None:
    assert _problems(page) == []


def test_the_check_finds_a_link_out_of_the_repository(tmp_path: Path) -> None:
    page = ROOT / "specs" / "README.md"
    assert _problems(page) == []
    assert LINK.findall("see [the reference](../../shared/reference/x.md)") == ["../../shared/reference/x.md"]
    assert RELATIVE.findall("is `../shared/reference/model-definitions.md`.") == [
        "../shared/reference/model-definitions.md"]
