"""The merge request's review of the change: the build against the release on the request's
target branch, as Markdown with pictures (`mpc diff`'s, made by the caller's function:
deploy/ does not import checks/, checks/diff_review.py makes it).

The release's files are written from the clone (core/git_tree.py) into the workdir, beside
the clone; the pictures go into a folder of their own there, which the deployment commits
into `test_pictures/` beside the protocol's. A target branch that does not exist yet has no
release: the review is left out. A review that fails says so instead: a deployment does not
fail for it.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

from mpc.deploy.repository import Clone

Review = Callable[[Path, Path], str]  # (release folder, pictures folder) → Markdown


def release_review(review: Review, clone: Clone, target: str, workdir: Path,
                   modelname: str) -> tuple[str, Path]:
    """(the Markdown, the folder of its pictures) of the build against branch `target`; ("", …)
    when the branch does not exist."""
    from mpc.core.git_tree import write_tree
    from mpc.core.gitrun import GitFailed

    pictures = workdir / f"{modelname}.review-pictures"
    shutil.rmtree(pictures, ignore_errors=True)
    sha = clone.remote_sha(target)
    if sha is None:
        return "", pictures
    release = workdir / f"{modelname}.release"
    shutil.rmtree(release, ignore_errors=True)
    try:
        write_tree(clone.folder, sha, release)
        return review(release, pictures), pictures
    except GitFailed as e:
        return f"(The changes against '{target}' could not be listed: {e.message}.)", pictures
    except Exception as e:  # a bug in the diff must not stop the delivery; it is said
        return (f"(The changes against '{target}' could not be listed: {type(e).__name__}: {e}. "
                "This is a bug in mpc.)"), pictures
    finally:
        shutil.rmtree(release, ignore_errors=True)
