"""Meshes whose package cannot be found → one error per package (E0654), not one per mesh.

A model whose description package is missing names it in every mesh (45 times for ANYmal):
the user needs to hear once which package to map, and how many files wait for it.
"""

from __future__ import annotations

from collections.abc import Iterable

from mpc.core.diagnostics import Diagnostic, Severity
from mpc.core.packages import package_of
from mpc.core.span import Span
from mpc.ir.geometry import Mesh

_SHOWN = 2  # the uses after the first that get a note of their own


def unfound_packages(uses: Iterable[tuple[str, str, Mesh]], where: Span) -> list[Diagnostic]:
    """E0654 for each package that the uses' meshes (link, element, mesh; in the model's
    order) name and that was not found: at the first use, naming the package, how many
    mesh files need it, with a note at the next uses and a count of the rest."""
    by_package: dict[str, list[tuple[str, str, Mesh]]] = {}
    for use in uses:
        source = use[2].source
        package = package_of(source.uri) if source.path is None else None
        if package is not None:
            by_package.setdefault(package, []).append(use)
    out = []
    for package, found in by_package.items():
        (link, element, mesh), rest = found[0], found[1:]
        files = len({m.source.uri for _, _, m in found})
        need = "1 mesh file needs it" if files == 1 else f"{files} mesh files need it"
        notes: list[tuple[Span | None, str]] = [
            (m.span or where, f"also mesh '{m.source.uri}' of a {e} of link '{lk}'")
            for lk, e, m in rest[:_SHOWN]]
        if len(rest) > _SHOWN:
            notes.append((None, f"and {len(rest) - _SHOWN} more uses of package '{package}'"))
        out.append(Diagnostic(
            Severity.ERROR, "E0654", f"{mesh.source.unresolved}; {need}, the first mesh "
            f"'{mesh.source.uri}' of a {element} of link '{link}'", mesh.span or where, tuple(notes),
            hint=f"map the package with --package {package}=DIR, or put the folder that holds it "
                 "(its package.xml names it) on ROS_PACKAGE_PATH"))
    return out
