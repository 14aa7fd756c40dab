"""Where a link or joint of a xacro model is written: in the xacro file or in a file it includes.

A xacro model is read from the URDF that xacro expands it to (backends/xacro_reader.py), so its
elements' spans are lines of that expansion, which exists in no file. Go to definition finds
the element in the sources instead:

1. the files: the xacro file, then each file it includes (`<xacro:include filename=…>`, in the
   order written, depth first), with the filename resolved as xacro resolves it — relative to
   the including file, `$(find pkg)/…` and `package://pkg/…` by the server's PackageResolver;
   a filename that other substitutions build (`$(arg …)`, `${…}`) is not followed, nor one
   that the rule of every file mpc reads refuses (PackageResolver.refusal);
2. the element whose name is written as it is (`<link name="base">`), in the first file that
   has one;
3. else the element whose name a macro puts together (`<link name="${name}_link">`), when
   exactly one such template in those files can give that name: the `${…}` parts stand for
   any text. Two templates that could both give it: no answer (the caller shows the file).
"""

from __future__ import annotations

import re
from pathlib import Path

from mpc.core.packages import PackageResolver
from mpc.core.span import Span

_INCLUDE = re.compile(r"<xacro:include\b[^>]*?\bfilename\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")
_FIND = re.compile(r"^\$\(find\s+([^)\s]+)\)(.*)$")
_EXPRESSION = re.compile(r"\$\{[^}]*\}")
_NOT_FILES = ("/proc/", "/sys/", "/dev/")


def find_element(top: Path, kind: str, name: str, resolver: PackageResolver) -> Span | None:
    """The span of `<kind name=…>` that makes the element `name` (1-based), or None."""
    texts = _sources(top, resolver)
    element = re.compile(rf"<{kind}\b[^>]*?\bname\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")
    templates: list[Span] = []
    for path, text in texts:
        for match in element.finditer(text):
            written = match.group(1) if match.group(1) is not None else match.group(2)
            if written == name:
                return _span(path, text, match)
            if "${" in written and _template(written).fullmatch(name):
                templates.append(_span(path, text, match))
    return templates[0] if len(templates) == 1 else None


def _sources(top: Path, resolver: PackageResolver) -> list[tuple[Path, str]]:
    """The xacro file and the files it includes, depth first, each once."""
    out: list[tuple[Path, str]] = []
    seen: set[Path] = set()

    def visit(path: Path, folder: Path) -> None:
        if resolver.refusal(path, folder) is not None:  # the rule of every file mpc reads
            return
        path = path.resolve()
        if path in seen or str(path).startswith(_NOT_FILES) or not path.is_file():
            return
        seen.add(path)
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            return
        out.append((path, text))
        for match in _INCLUDE.finditer(text):
            included = _resolve(match.group(1) or match.group(2) or "", path.parent, resolver)
            if included is not None:
                visit(included, path.parent)

    visit(top, top.parent)
    return out


def _resolve(spec: str, folder: Path, resolver: PackageResolver) -> Path | None:
    """An include's filename as xacro resolves it, or None when other substitutions build it."""
    find = _FIND.match(spec)
    if find:
        package_folder = resolver.find(find.group(1), folder)
        rest = find.group(2)
        if package_folder is None or "$(" in rest or "${" in rest:
            return None
        return Path(str(package_folder) + rest)
    if "$(" in spec or "${" in spec:
        return None
    if spec.startswith("package://"):
        return resolver.locate(spec, folder)[0]
    return folder / spec


def _template(written: str) -> re.Pattern[str]:
    """A name with `${…}` expressions as a pattern: the expressions match any text."""
    parts = _EXPRESSION.split(written)
    return re.compile(".+?".join(re.escape(part) for part in parts))


def _span(path: Path, text: str, match: re.Match[str]) -> Span:
    line = text.count("\n", 0, match.start()) + 1
    col = match.start() - (text.rfind("\n", 0, match.start()) + 1) + 1
    end = match.end() - (text.rfind("\n", 0, match.end()) + 1) + 1
    return Span(str(path), line, col, text.count("\n", 0, match.end()) + 1, end)
