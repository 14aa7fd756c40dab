"""A model of the plan and its state from the last build → its fingerprint before building,
and which of its stages (or its last failure) still hold, so they need not run again.

Nothing is built here; the only write is a state whose recorded file times are refreshed
(when only the times changed), so the next run stats files instead of hashing them.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from mpc.core.packages import PackageResolver
from mpc.core.version import source_version
from mpc.pipeline.fingerprint import data_digest, dep_name, deps_current, digest
from mpc.pipeline.plan import Plan, PlannedModel
from mpc.pipeline.store import Store


class Freshness:
    """The cache checks of one run: the plan, the build folder's state, the stages of the
    run, and the options that are part of every fingerprint (`--package`, `--werror`);
    `force` ignores the cache."""

    def __init__(self, plan: Plan, store: Store, stages: tuple[str, ...], package_map: Mapping[str, Path],
                 werror: bool, force: bool, post_processing: bool = True) -> None:
        self.plan, self.store, self.stages, self.force = plan, store, stages, force
        # Package folders inside the root are named relative to it, as the files a build read.
        packages = repr(sorted((k, dep_name(v, plan.root)) for k, v in package_map.items()))
        # a build without its post_processing is another build (nothing said: the same as before)
        skipped = () if post_processing else ("no post_processing",)
        self.options = digest(source_version(), packages, str(werror), *skipped)
        self.resolver = PackageResolver(package_map=dict(package_map))  # where packages are now

    def before_build(self, model: PlannedModel, this_run: Mapping[str, str | None]) -> str:
        """What is known before building: mpc and the options, the definition as planned,
        and the parents' fingerprints (`this_run`: those of the models finished in this run)."""
        return digest(self.options, data_digest(model.data),
                      *(f"{p}={self.parent_fingerprint(p, this_run)}" for p in sorted(model.parents)))

    def parent_fingerprint(self, parent: str, this_run: Mapping[str, str | None]) -> str:
        """A parent's compile fingerprint: from this run, else from its last build."""
        fingerprint = this_run.get(parent) or self.store.state(parent).get("fingerprint")
        return fingerprint or "unbuilt:" + data_digest(self.plan.models[parent].data)

    def last_failure(self, name: str, pre: str) -> dict[str, Any] | None:
        """The model's last compile failure, when nothing it depends on changed since: compiling
        is deterministic, so it would fail again the same way."""
        failure = self.store.state(name).get("failure")
        if self.force or failure is None or failure["pre"] != pre:
            return None
        return failure if deps_current(failure["deps"], self.plan.root, self.resolver) is not None else None

    def cached_stages(self, name: str, pre: str) -> list[str]:
        """The stages (of `stages`) whose result from an earlier run still holds."""
        state = self.store.state(name)
        done = state.get("stages", {})
        if (self.force or state.get("pre") != pre or "compile" not in done
                or not self.store.output(name).is_dir()):
            return []
        deps = deps_current(state.get("deps", []), self.plan.root, self.resolver)
        if deps is None:
            return []
        if deps != state.get("deps", []):  # only times changed: remember them, so the next run stats only
            with contextlib.suppress(OSError):  # a state that cannot be written costs hashing, no more
                self.store.save_state(name, {**state, "deps": deps})
        fingerprint = state["fingerprint"]
        return [s for s in self.stages if s == "compile"
                or done.get(s, {}).get("fingerprint") == self.stage_fingerprint(fingerprint, s)]

    def stage_fingerprint(self, compile_fingerprint: str, stage: str) -> str:
        """A stage's fingerprint: compile's, the stage and the pipeline's settings."""
        if stage == "compile":
            return compile_fingerprint
        # The list of models is not a setting of any one model's stage: adding a model to
        # the pipeline must not run the others' tests again.
        settings = {k: v for k, v in self.plan.settings.items() if k != "model_definitions"}
        return digest(compile_fingerprint, stage, data_digest(settings))
