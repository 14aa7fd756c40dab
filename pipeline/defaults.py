"""A definition Document + the pipeline's `default_…` settings → the definition the pipeline builds.

The front end calls this hook (`Options.defaults`) after a definition's own `defaults` chain
is merged and before the schema; it validates nothing itself.

Merge rule (specs/pipeline.md): the pipeline's defaults are the outermost layer, below
every defaults file of the model.
- `default_export_config` is the model's `export_config` when the model (after its own
  defaults chain) has none; a model's own export_config replaces it whole.
- `default_test` and `default_deployment` are merged under the model's `test` and
  `deployment` with the rule of defaults files (compiler/inherit.py): mappings merge key
  by key, lists concatenate (pipeline items first), other values are the model's.
Values taken from the pipeline keep their spans in pipeline.yml, so a mistake in a
default is reported where it was written.
"""

from __future__ import annotations

from typing import Any

# The merge of defaults files, reused so both layers follow one rule.
from mpc.compiler.inherit import copy_value, forget_spans, merge_value
from mpc.core.record import record
from mpc.core.yaml_source import Document

_MERGED = (("test", "default_test"), ("deployment", "default_deployment"))


@record
class PipelineDefaults:
    """The `default_…` settings of one pipeline file, applied to each definition it builds."""

    pipeline: Document

    def settings(self) -> dict[str, Any]:
        data = self.pipeline.data.get("pipeline") if isinstance(self.pipeline.data, dict) else None
        return data if isinstance(data, dict) else {}

    def __call__(self, doc: Document) -> Document:
        settings = self.settings()
        model = doc.data.get("model") if isinstance(doc.data, dict) else None
        wanted = [k for k in ("default_export_config", "default_test", "default_deployment")
                  if settings.get(k) is not None]
        if not isinstance(model, dict) or not wanted:
            return doc
        out = Document(doc.file, None, dict(doc.values), dict(doc.keys))
        model = dict(model)
        if settings.get("default_export_config") is not None and model.get("export_config") is None:
            model["export_config"] = self._take("default_export_config", ("model", "export_config"), out)
        for key, setting in _MERGED:
            if settings.get(setting) is None:
                continue
            base = self._take(setting, ("model", key), out, forget=model.get(key))
            if model.get(key) is not None:
                model[key] = merge_value(base, doc.data["model"][key], doc, ("model", key), ("model", key),
                                         out)
                if ("model", key) in doc.keys:
                    out.keys[("model", key)] = doc.keys[("model", key)]
            else:
                model[key] = base
        out.data = {**doc.data, "model": model}
        return out

    def _take(self, setting: str, path: tuple[str, ...], out: Document, forget: Any = None) -> Any:
        """A copy of the pipeline's `setting`, its spans recorded at `path` of `out`."""
        if forget is not None:
            forget_spans(forget, path, out)
        src = ("pipeline", setting)
        if src in self.pipeline.keys:
            out.keys[path] = self.pipeline.keys[src]
        return copy_value(self.settings()[setting], self.pipeline, src, path, out)
