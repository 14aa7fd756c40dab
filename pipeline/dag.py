"""The models of a pipeline as a graph (edges: derived_base) → build order, cycles, dependants.

Pure functions over names; nothing here reads files. The order is the pipeline file's
order only as a tie-break, so the file's order never decides whether a build works.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping


def cycles(parents: Mapping[str, Iterable[str]]) -> list[list[str]]:
    """Every elementary loop found by a depth-first walk, each as [a, b, …, a]; at most one per
    strongly connected part, which is what a user needs to see to break it."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []
    found: list[list[str]] = []

    def visit(node: str) -> None:
        state[node] = 1
        path.append(node)
        for parent in parents.get(node, ()):
            if parent not in parents:
                continue
            if state.get(parent) == 1:
                found.append([*path[path.index(parent):], parent])
            elif parent not in state:
                visit(parent)
        path.pop()
        state[node] = 2

    for node in parents:
        if node not in state:
            visit(node)
    return found


def order(parents: Mapping[str, Iterable[str]]) -> list[str]:
    """The nodes with every parent before its children (Kahn's algorithm); ties keep the
    mapping's order. Nodes on a cycle, and those below them, are left out."""
    pending = {n: {p for p in ps if p in parents} for n, ps in parents.items()}
    out: list[str] = []
    ready = [n for n in parents if not pending[n]]
    while ready:
        node = ready.pop(0)
        out.append(node)
        for child in parents:
            if node in pending[child]:
                pending[child].discard(node)
                if not pending[child] and child not in out and child not in ready:
                    ready.append(child)
    return out


def children_of(parents: Mapping[str, Iterable[str]]) -> dict[str, list[str]]:
    """The inverse edges: for each node, the nodes that name it as a parent."""
    children: dict[str, list[str]] = {n: [] for n in parents}
    for node, ps in parents.items():
        for p in ps:
            if p in children:
                children[p].append(node)
    return children


def descendants(parents: Mapping[str, Iterable[str]], node: str) -> set[str]:
    """Every node that depends on `node`, directly or through others."""
    children = children_of(parents)
    seen: set[str] = set()
    todo = list(children.get(node, ()))
    while todo:
        n = todo.pop()
        if n not in seen:
            seen.add(n)
            todo.extend(children.get(n, ()))
    return seen

