"""Definition Document → the same with its `defaults` chain merged in and `@key@` substituted.

Does not validate the merged model (the schema does that) and does not scan mapping keys.

A definition names a defaults file with a top-level `defaults: <path>` (relative to the
folder of the file that names it). That file holds `default_model:` and may name its own
`defaults:`; chains have any length. The chain merges parent-first: the deepest
`default_model` is the base, each nearer file overrides it, the definition's `model` last.

Merge rule (Phobos's `patch_dict`, kept): mappings merge key by key, recursively; lists
concatenate, inherited items first (tests and export configs accumulate); anything else —
scalars, `null`, or a type mismatch such as a list over a mapping — is replaced by the
nearer file's value.

Then every string value that is exactly `@key@` becomes the value of `key` in the merged
`model` mapping, keeping its type; `@key@` inside a longer string gets the value's text.
Phobos pastes JSON text instead, so numbers vanish and lists lose their brackets; and it
substitutes only when `defaults` is used, where we always do. Substituted values are not
scanned again. Only `@name@` with `name` an identifier counts (`a@b.c` is left alone).

    base.yml:   default_model: {robotname: r1, mass: 2, test: {tests: [a]}}
    model.yml:  defaults: base.yml
                model: {mass: 3, modelname: "@robotname@-arm", test: {tests: [b]}}
    →           model: {robotname: r1, mass: 3, test: {tests: [a, b]}, modelname: r1-arm}
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

from mpc.core import yaml_source as source
from mpc.core.diagnostics import Sink, did_you_mean
from mpc.core.files import input_problem, project_root, resolved
from mpc.core.span import Span
from mpc.core.yaml_source import Document, Path_

_DEFAULTS_KEYS = ("defaults", "default_model")
_SUBST = re.compile(r"@([A-Za-z_][A-Za-z0-9_]*)@")


def resolve(doc: Document, path: Path, sink: Sink) -> Document | None:
    """A definition file with its `defaults` chain merged in and `@key@` substituted.

    The result is a new Document whose data has no `defaults` key and whose span tables
    give, for every path of the merged data, the span where that value (or key) was
    written — in whichever file that was. None when there were errors.
    """
    errors = sink.error_count
    merged = doc
    if isinstance(doc.data, dict) and "defaults" in doc.data:
        chain = _chain(doc, path, sink)
        if chain is None or sink.error_count > errors:
            return None
        merged = _merge_chain(doc, chain)
    result = _substitute(merged, sink)
    return None if sink.error_count > errors else result


# Loading the chain


def _chain(doc: Document, path: Path, sink: Sink) -> list[Document] | None:
    """The defaults files named from `doc`, nearest first; None after an error that ends the walk."""
    seen: list[tuple[Path, str, Span | None]] = [(resolved(path), "", None)]  # file, name, named at
    chain: list[Document] = []
    roots = (project_root(path.parent),)
    current, current_path = doc, path
    while isinstance(current.data, dict) and "defaults" in current.data:
        written = current.data["defaults"]
        at = current.value_span(("defaults",))
        if not isinstance(written, str) or not written:
            sink.error(at, "E0203", f"'defaults' must be the path of a defaults file, got {written!r}")
            return None
        target = current_path.parent / written
        real = resolved(target)
        for i, (other, _, _) in enumerate(seen):
            if other == real:
                names = [written, *(name for _, name, _ in seen[i + 1:]), written]
                notes = tuple((span, "named here") for _, _, span in seen[i + 1:] if span is not None)
                sink.error(at, "E0220", f"defaults cycle: {' → '.join(names)}", notes=notes)
                return None
        if not target.exists():
            sink.error(at, "E0601", f"defaults file '{written}' does not exist",
                       hint=f"the path is relative to the folder of '{current.file}'")
            return None
        if why := input_problem(target, roots):
            sink.error(at, "E0650", f"defaults file '{written}' is not read: {why}",
                       hint="a defaults file lies inside the definition's project (its git work "
                       "tree, else its folder)")
            return None
        display = os.path.normpath(os.path.join(os.path.dirname(current.file), written))
        loaded = source.load(target, sink, display=display, origin=at)
        if loaded is None:
            return None
        _check_defaults_file(loaded, sink)
        seen.append((real, written, at))
        chain.append(loaded)
        current, current_path = loaded, target
    return chain


def _check_defaults_file(doc: Document, sink: Sink) -> None:
    """Report what a defaults file has besides `defaults` and a `default_model` mapping."""
    if not isinstance(doc.data, dict):
        sink.error(doc.value_span(()), "E0203",
                   f"defaults file '{doc.file}' must be a mapping with a 'default_model' key")
        return
    for key in doc.data:
        if key not in _DEFAULTS_KEYS:
            sink.error(doc.span((key,)), "E0201",
                       f"unknown key '{key}' in a defaults file{did_you_mean(key, set(_DEFAULTS_KEYS))}")
    if "default_model" not in doc.data:
        sink.error(Span.of_file(doc.file), "E0203", f"defaults file '{doc.file}' has no 'default_model'")
    elif not isinstance(doc.data["default_model"], dict):
        sink.error(doc.value_span(("default_model",)), "E0203",
                   f"'default_model' in '{doc.file}' must be a mapping")


# Merging, with spans re-keyed to the output paths


def _merge_chain(doc: Document, chain: list[Document]) -> Document:
    """`doc` with the `default_model`s of `chain` (nearest first) merged under its `model`."""
    out = Document(doc.file, None)
    src_path: Path_ = ("default_model",)
    model = copy_value(chain[-1].data["default_model"], chain[-1], src_path, ("model",), out)
    for layer in reversed(chain[:-1]):
        model = merge_value(model, layer.data["default_model"], layer, src_path, ("model",), out)
    if "model" in doc.data:
        model = merge_value(model, doc.data["model"], doc, ("model",), ("model",), out)
        model_key = doc.keys.get(("model",))
    else:
        model_key = chain[0].keys.get(("default_model",))
    _set(out.keys, ("model",), model_key)
    # The model goes first even when only the defaults had one: Phobos requires it first.
    data: dict[str, Any] = {"model": model}
    for key, value in doc.data.items():
        if key not in ("defaults", "model"):
            data[key] = copy_value(value, doc, (key,), (key,), out)
            _set(out.keys, (key,), doc.keys.get((key,)))
    _set(out.values, (), doc.values.get(()))
    out.data = data
    return out


def merge_value(old: Any, new: Any, src: Document, src_path: Path_, out_path: Path_, out: Document) -> Any:
    """`new` (at `src_path` in `src`) over `old` (already at `out_path` in `out`), per the merge rule."""
    if isinstance(old, dict) and isinstance(new, dict):
        result = dict(old)
        for key, value in new.items():
            sub, sub_src = (*out_path, key), (*src_path, key)
            if key in old:
                result[key] = merge_value(old[key], value, src, sub_src, sub, out)
            else:
                result[key] = copy_value(value, src, sub_src, sub, out)
            _set(out.keys, sub, src.keys.get(sub_src))
    elif isinstance(old, list) and isinstance(new, list):
        result = old + [copy_value(item, src, (*src_path, i), (*out_path, len(old) + i), out)
                        for i, item in enumerate(new)]
    else:
        forget_spans(old, out_path, out)
        return copy_value(new, src, src_path, out_path, out)
    # A merged container is attributed to the nearer file, where the user last wrote it.
    _set(out.values, out_path, src.values.get(src_path))
    return result


def copy_value(value: Any, src: Document, src_path: Path_, out_path: Path_, out: Document) -> Any:
    """A fresh copy of `value`, recording its spans (and those of everything in it) at `out_path`."""
    _set(out.values, out_path, src.values.get(src_path))
    if isinstance(value, dict):
        result = {}
        for key, item in value.items():
            _set(out.keys, (*out_path, key), src.keys.get((*src_path, key)))
            result[key] = copy_value(item, src, (*src_path, key), (*out_path, key), out)
        return result
    if isinstance(value, list):
        return [copy_value(item, src, (*src_path, i), (*out_path, i), out) for i, item in enumerate(value)]
    return value


def forget_spans(value: Any, path: Path_, out: Document) -> None:
    """Drop the spans below `path` of a value that is being replaced."""
    if isinstance(value, dict):
        for key, item in value.items():
            out.keys.pop((*path, key), None)
            out.values.pop((*path, key), None)
            forget_spans(item, (*path, key), out)
    elif isinstance(value, list):
        for i, item in enumerate(value):
            out.values.pop((*path, i), None)
            forget_spans(item, (*path, i), out)


def _set(table: dict[Path_, Span], path: Path_, span: Span | None) -> None:
    # Merge keys (`<<`) leave some paths without spans in source.load; those stay absent.
    if span is not None:
        table[path] = span


# Substitution


def _substitute(doc: Document, sink: Sink) -> Document:
    """`doc` with `@key@` replaced in every string value; `doc` itself when there were none."""
    data = doc.data if isinstance(doc.data, dict) else {}
    model = data.get("model") if isinstance(data.get("model"), dict) else {}
    out = Document(doc.file, None, dict(doc.values), dict(doc.keys))
    changed = False

    def walk(value: Any, path: Path_) -> Any:
        nonlocal changed
        if isinstance(value, dict):
            return {k: walk(v, (*path, k)) for k, v in value.items()}
        if isinstance(value, list):
            return [walk(v, (*path, i)) for i, v in enumerate(value)]
        if not isinstance(value, str) or "@" not in value:
            return value
        at = doc.value_span(path)
        whole = _SUBST.fullmatch(value)
        if whole:
            name = whole.group(1)
            if name not in model:
                _unknown(name, model, at, sink)
                return value
            changed = True
            result = copy_value(model[name], doc, ("model", name), path, out)
            # The value keeps the span of the `@key@`; what is inside it, the spans where it was written.
            out.values[path] = at
            return result

        def text(match: re.Match[str]) -> str:
            nonlocal changed
            name = match.group(1)
            if name not in model:
                _unknown(name, model, at, sink)
                return match.group(0)
            found = model[name]
            if found is None or isinstance(found, dict | list):
                kind = "null" if found is None else "a mapping" if isinstance(found, dict) else "a list"
                sink.error(at, "E0222", f"substitution '@{name}@' is {kind} and cannot be part of a longer "
                           f"string", hint=f"write '@{name}@' alone to use the value itself")
                return match.group(0)
            changed = True
            return _text(found)

        return _SUBST.sub(text, value)

    out.data = walk(doc.data, ())
    return out if changed else doc


def _unknown(name: str, model: dict[str, Any], at: Span, sink: Sink) -> None:
    near = did_you_mean(f"@{name}@", {f"@{key}@" for key in model if isinstance(key, str)})
    sink.error(at, "E0221", f"unknown substitution '@{name}@'{near}")


def _text(value: Any) -> str:
    """A scalar as it reads in YAML: true/false, the shortest float that round-trips."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return value if isinstance(value, str) else repr(value)
