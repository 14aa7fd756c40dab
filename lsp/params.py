"""The params each LSP method of the server takes, and what is wrong with params that do not fit.

A method's params are checked against its shape before its handler runs, so that a handler
reads plain dicts (lsp/structures.py) without checking them again. Only the fields the server
reads are required; other fields are let through, as LSP's future versions add some. The
problems are named by where they are, as JSON paths: `required field missing @
$.params.position`, `expected an integer ≥ 0 @ $.params.position.line`.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import field
from typing import Any

from mpc.core.record import record


class Shape:
    """What a JSON value must be."""

    def problems(self, value: Any, at: str) -> Iterator[str]:
        raise NotImplementedError


@record
class Scalar(Shape):
    """A JSON scalar: `kinds` the Python types json.loads gives it, `name` in the problem."""

    kinds: tuple[type, ...]
    name: str
    least: int | None = None  # the least number allowed

    def problems(self, value: Any, at: str) -> Iterator[str]:
        fits = isinstance(value, self.kinds) and not (isinstance(value, bool) and bool not in self.kinds)
        if not fits or (self.least is not None and value < self.least):
            yield f"expected {self.name} @ {at}"


@record
class Obj(Shape):
    """An object with these fields (and any others); `optional` ones may be left out."""

    fields: dict[str, Shape]
    optional: dict[str, Shape] = field(default_factory=dict)

    def problems(self, value: Any, at: str) -> Iterator[str]:
        if not isinstance(value, dict):
            yield f"expected an object @ {at}"
            return
        for name, shape in self.fields.items():
            if name not in value:
                yield f"required field missing @ {at}.{name}"
            else:
                yield from shape.problems(value[name], f"{at}.{name}")
        for name, shape in self.optional.items():
            if name in value:
                yield from shape.problems(value[name], f"{at}.{name}")


@record
class Items(Shape):
    """An array of values of one shape."""

    item: Shape

    def problems(self, value: Any, at: str) -> Iterator[str]:
        if not isinstance(value, list):
            yield f"expected an array @ {at}"
            return
        for i, item in enumerate(value):
            yield from self.item.problems(item, f"{at}[{i}]")


ANY_OBJECT = Scalar((dict,), "an object")
STRING = Scalar((str,), "a string")
INTEGER = Scalar((int,), "an integer")
UINTEGER = Scalar((int,), "an integer ≥ 0", least=0)
ID = Scalar((int, str), "a number or a string")

TEXT_DOCUMENT = Obj({"uri": STRING})
POSITION = Obj({"line": UINTEGER, "character": UINTEGER})
RANGE = Obj({"start": POSITION, "end": POSITION})
AT = Obj({"textDocument": TEXT_DOCUMENT, "position": POSITION})
DIAGNOSTIC = Obj({"range": RANGE, "message": STRING})

# The params of each method the server serves; a method without params takes any (or none).
PARAMS: dict[str, Shape] = {
    "initialize": Obj({"capabilities": ANY_OBJECT}),
    "$/cancelRequest": Obj({"id": ID}),
    "textDocument/didOpen": Obj({"textDocument": Obj(
        {"uri": STRING, "languageId": STRING, "version": INTEGER, "text": STRING})}),
    "textDocument/didChange": Obj({
        "textDocument": Obj({"uri": STRING, "version": INTEGER}),
        # a change with a range replaces that range, one without it the whole text
        "contentChanges": Items(Obj({"text": STRING}, optional={"range": RANGE}))}),
    "textDocument/didSave": Obj({"textDocument": TEXT_DOCUMENT}),
    "textDocument/didClose": Obj({"textDocument": TEXT_DOCUMENT}),
    "textDocument/completion": AT,
    "textDocument/hover": AT,
    "textDocument/definition": AT,
    "textDocument/documentSymbol": Obj({"textDocument": TEXT_DOCUMENT}),
    "textDocument/rename": Obj({"textDocument": TEXT_DOCUMENT, "position": POSITION, "newName": STRING}),
    "textDocument/codeAction": Obj({"textDocument": TEXT_DOCUMENT, "range": RANGE,
                                    "context": Obj({"diagnostics": Items(DIAGNOSTIC)})}),
}


def problems(method: str, params: Any) -> list[str]:
    """What is wrong with `params` for `method` (nothing for a method without a shape here)."""
    shape = PARAMS.get(method)
    if shape is None:
        return []
    return list(shape.problems(params, "$.params"))
