"""`input_models` (AST) → ir.Inputs: each input's file, or its repository, and its xacro arguments.

It resolves `package://` names to files (core/packages.py) but reads no model and clones no
repository (compiler/inputs.py does, after the passes).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from mpc.compiler.lower_context import LowerContext
from mpc.core.files import resolved
from mpc.core.packages import PackageResolver
from mpc.ir.program import Input, RepoRef


def resolve_file(written: str, base_dir: Path, resolver: PackageResolver) -> Path:
    """A file named in a definition: `package://…`, absolute, or relative to its folder."""
    if written.startswith("package://"):
        path, _ = resolver.locate(written, base_dir)
        if path is not None:
            return path
    return resolved(base_dir / written)


def lower_inputs(ctx: LowerContext) -> dict[str, Input]:
    out = {}
    for name, entry in ctx.model.input_models.items():
        args, env = xacro_args(ctx, entry), xacro_env(ctx, entry)
        if entry.basefile is not None:
            folder = ctx.folder_of(entry, "basefile")
            path: Path | None = resolve_file(entry.basefile, folder, ctx.resolver)
            found, unresolved = ctx.resolver.locate(entry.basefile, folder)
            if entry.basefile.startswith("package://") and found is None:
                ctx.sink.error(entry.value_span("basefile"), "E0601",
                               f"basefile '{entry.basefile}' of input model '{name}' cannot be "
                               f"found: {unresolved}",
                               hint="map the package with --package NAME=DIR or ROS_PACKAGE_PATH")
                path = None
            out[name] = Input(name=name, kind="basefile", span=entry.value_span("basefile"),
                              path=path, is_human=entry.is_human, xacro_args=args, xacro_env=env)
        elif entry.derived_base is not None:
            out[name] = Input(name=name, kind="derived_base", span=entry.value_span("derived_base"),
                              path=resolved(ctx.folder_of(entry, "derived_base") / entry.derived_base),
                              is_human=entry.is_human,
                              smurf_data=ctx.model.inherit_smurf_properties)
        elif entry.repo is not None:
            r = entry.repo
            out[name] = Input(name=name, kind="repo", path=None, span=entry.value_span("repo"),
                              is_human=entry.is_human, xacro_args=args, xacro_env=env,
                              repo=RepoRef(git=r.git, commit=r.commit, branch=r.branch,
                                           model_in_repo=r.model_in_repo,
                                           submechanisms_in_repo=r.submechanisms_in_repo))
    return out


def xacro_args(ctx: LowerContext, entry: Any) -> tuple[tuple[str, str], ...]:
    """The input's `xacro_args` as text (xacro's arguments are strings); a warning when its
    model file is no xacro, which ignores them."""
    if entry.xacro_args is None or not _is_xacro(ctx, entry, "xacro_args"):
        return ()
    text = {True: "true", False: "false"}
    out = []
    for key, value in sorted(entry.xacro_args.items()):
        if not isinstance(value, str | int | float | bool):
            ctx.sink.error(entry.value_span("xacro_args"), "E0240", f"xacro argument '{key}' is a "
                           "string, a number or a boolean (xacro's arguments are text)")
            continue
        out.append((key, text[value] if isinstance(value, bool) else str(value)))
    return tuple(out)


def xacro_env(ctx: LowerContext, entry: Any) -> tuple[str, ...]:
    """The environment variables the input's xacro may read (`xacro_env`), sorted, each once;
    E0672 for one that is no variable name."""
    if entry.xacro_env is None or not _is_xacro(ctx, entry, "xacro_env"):
        return ()
    out = []
    for i, name in enumerate(entry.xacro_env):
        if not _VARIABLE.fullmatch(name):
            ctx.sink.error(entry.value_span("xacro_env"), "E0672", f"xacro_env entry {i + 1}, "
                           f"{name!r}, is not the name of an environment variable (letters, digits, '_')")
            continue
        out.append(name)
    return tuple(sorted(set(out)))


_VARIABLE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _is_xacro(ctx: LowerContext, entry: Any, key: str) -> bool:
    """Whether the input's model file is a xacro; W0622 at `key` (which applies to one) if not."""
    model = entry.basefile or (entry.repo.model_in_repo if entry.repo is not None else "")
    if not model.endswith(".xacro"):
        ctx.sink.warning(entry.key_span(key), "W0622", f"{key} apply to a .xacro model "
                         f"file; '{model}' is none, so they are ignored")
        return False
    return True
