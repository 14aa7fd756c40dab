"""Where a deployed model comes from → the commit message and the merge request's footer.

It records the definition repository's commit, mpc's version, each input model's commit
(for files in a git repository, and `repo` inputs) or SHA-256 (other files), and the test
summary. It reads files and repositories; it writes nothing.
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass
from pathlib import Path

from mpc.core.version import mpc_version
from mpc.deploy.gitcmd import scrub, without_credentials
from mpc.ir.program import Program


def _repository_state(path: Path) -> tuple[str, bool, str] | None:
    """(commit, dirty, path in the repository) of the git working copy holding `path`, or None."""
    from mpc.core.gitrun import GitFailed, git

    try:
        folder = path if path.is_dir() else path.parent
        top = Path(git("rev-parse", "--show-toplevel", cwd=folder)).resolve()  # fails in a bare one
        commit = git("rev-parse", "--verify", "HEAD^{commit}", cwd=folder)
        rel = path.resolve().relative_to(top).as_posix() if path.resolve().is_relative_to(top) else str(path)
        status = git("status", "--porcelain", "--untracked-files=all", "--", ".", cwd=top) if rel == "." \
            else git("status", "--porcelain", "--untracked-files=all", "--", rel, cwd=top)
    except (GitFailed, ValueError, OSError):  # no repository, no commit yet, or git failing
        return None
    return commit, bool(status.strip()), rel


def _sha256(path: Path) -> str | None:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return None


@dataclass(frozen=True)
class Provenance:
    """What a deployment records. definition: `<commit>[+dirty]` of the definitions, or None;
    inputs: one line per input model; tests: the test summary."""

    definition: str | None
    definition_file: str | None
    version: str
    inputs: tuple[str, ...]
    tests: str


def provenance(program: Program, definition_repo: Path | None, protocol: str | None,
               tests_failed: bool) -> Provenance:
    """The provenance of `program`, built from the files it names."""
    definition = definition_file = None
    file = Path(program.span.file) if program.span.file else None
    where = definition_repo or (file.parent if file else None)
    if where is not None:
        state = _repository_state(where)
        if state is not None:
            definition = state[0] + ("+dirty" if state[1] else "")
        if file is not None:
            file_state = _repository_state(file) if state is not None else None
            definition_file = file_state[2] if file_state else file.name
    inputs = []
    for name, inp in sorted(program.inputs.items()):
        if inp.repo is not None:
            rev = inp.repo.commit or (f"branch {inp.repo.branch}" if inp.repo.branch else "default branch")
            inputs.append(f"{name}: {without_credentials(inp.repo.git)} {rev} {inp.repo.model_in_repo}")
            continue
        if inp.path is None:
            inputs.append(f"{name}: {inp.kind}")
            continue
        state = _repository_state(inp.path)
        digest = _sha256(inp.path)
        parts = [f"{name}: {inp.kind} {inp.path.name}"]
        if state is not None:
            parts.append(f"commit {state[0]}{'+dirty' if state[1] else ''}")
        if digest is not None:
            parts.append(f"sha256 {digest}")
        inputs.append(" ".join(parts))
    return Provenance(definition, definition_file, mpc_version(), tuple(inputs),
                      test_summary(protocol, tests_failed))


_COUNTS = re.compile(r"\b\d+ (?:passed|failed|skipped)\b(?:[,;]? *\d+ (?:passed|failed|skipped)\b)*")


def test_summary(protocol: str | None, tests_failed: bool) -> str:
    """`passed` / `failed` / `not run`, with the protocol's own counts when it states them."""
    if protocol is None:
        return "failed" if tests_failed else "not run"
    outcome = "failed" if tests_failed else "passed"
    counts = _COUNTS.search(protocol)
    return f"{outcome} ({counts.group(0)})" if counts else outcome


def commit_message(program: Program, prov: Provenance) -> str:
    """`[mpc] Update <modelname>` and one line per fact; no shell ever sees it."""
    lines = [f"[mpc] Update {program.modelname}", ""]
    if prov.definition:
        lines.append(f"Definition: {prov.definition_file or '?'} at commit {prov.definition}")
    elif prov.definition_file:
        lines.append(f"Definition: {prov.definition_file} (not in a git repository)")
    lines.append(f"mpc: {prov.version}")
    lines.append(f"Tests: {prov.tests}")
    if prov.inputs:
        lines.append("Input models:")
        lines.extend(f"  {line}" for line in prov.inputs)
    return scrub("\n".join(lines) + "\n")


def footer(prov: Provenance) -> str:
    """The line merge requests end with: where the model comes from."""
    at = f" at definition commit {prov.definition}" if prov.definition else ""
    return f"Generated by mpc {prov.version}{at}."
