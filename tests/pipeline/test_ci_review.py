"""`mpc ci review`: in a merge request's pipeline, every model's changes against the request's
base commit, posted as one comment: to GitLab's notes API (a recording fake server here) and
to GitHub's issue comments (the deploy tests' fake GitHub); outside one, nothing."""

from __future__ import annotations

import json
import threading
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import git
import pytest

from tests.checks.test_diff import arm
from tests.conftest import write
from tests.deploy.test_github import FakeGitHub, github  # noqa: F401  (the fixture)
from tests.pipeline.helpers import mpc

TOKEN = "glpat-SECRETtoken123456"
NO_CI = {"CI_MERGE_REQUEST_IID": "", "GITHUB_EVENT_NAME": "", "GITHUB_EVENT_PATH": "", "GITLAB_TOKEN": "",
         "MPC_GITLAB_TOKEN": ""}


class FakeGitLab(ThreadingHTTPServer):
    """Records every request; answers a note as GitLab does (201)."""

    def __init__(self) -> None:
        super().__init__(("127.0.0.1", 0), GitLabHandler)
        self.requests: list[dict] = []

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.server_address[1]}"


class GitLabHandler(BaseHTTPRequestHandler):
    server: FakeGitLab

    def log_message(self, *args: object) -> None:
        pass

    def do_POST(self) -> None:
        body = json.loads(self.rfile.read(int(self.headers.get("Content-Length") or 0)))
        self.server.requests.append({"path": self.path, "token": self.headers.get("PRIVATE-TOKEN"),
                                     "body": body})
        data = json.dumps({"id": 1, "body": body["body"]}).encode()
        self.send_response(201)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)


@pytest.fixture
def gitlab() -> Iterator[FakeGitLab]:
    fake = FakeGitLab()
    thread = threading.Thread(target=fake.serve_forever, daemon=True)
    thread.start()
    yield fake
    fake.shutdown()
    fake.server_close()


def definitions(tmp_path: Path) -> tuple[Path, str]:
    """A definitions repository: the arm, then a commit narrowing its shoulder's limits. Its
    folder and the first commit (the merge request's base)."""
    top = tmp_path / "defs"
    repo = git.Repo.init(top, initial_branch="main")
    arm(top / "model")
    write(top / "pipeline.yml", "pipeline:\n  root: .\n  model_definitions:\n    - arm.yml\n")
    write(top / "arm.yml", """
        model:
          robotname: arm
          modelname: arm
          input_models:
            base:
              basefile: model/arm.urdf
          assemble:
            model: base
          export_config:
            - type: urdf
        """)
    who = git.Actor("a", "a@example.org")
    repo.index.add(["pipeline.yml", "arm.yml", "model/arm.urdf", "model/ball.stl"])
    base = repo.index.commit("the arm", author=who, committer=who).hexsha
    arm(top / "model", limit="1.0")
    repo.index.add(["model/arm.urdf"])
    repo.index.commit("a narrower shoulder", author=who, committer=who)
    return top, base


def review(base: str) -> str:
    return ("<!-- mpc ci review -->\n"
            f"## Changes of `arm`: `arm.yml@{base[:12]}` → `arm.yml`\n\n"
            "**1 change** beyond the tolerances (mass 0.01 kg, distance 0.003 m, angle 0.03 rad, "
            "other 0.01).\n\n"
            "- joint `shoulder`: limit lower -2.5 → -1, upper 2.5 → 1\n")


def test_gitlab_gets_the_review_as_a_note(tmp_path: Path, gitlab: FakeGitLab) -> None:
    top, base = definitions(tmp_path)
    done = mpc("ci", "review", "pipeline.yml", cwd=top, cache=tmp_path / "cache", environ={
        **NO_CI, "CI_MERGE_REQUEST_IID": "5", "CI_API_V4_URL": f"{gitlab.url}/api/v4",
        "CI_MERGE_REQUEST_PROJECT_ID": "42", "CI_MERGE_REQUEST_DIFF_BASE_SHA": base,
        "MPC_GITLAB_TOKEN": TOKEN})
    assert done.returncode == 0, done.stderr
    assert done.stderr == "posted the review to merge request !5\n"
    [note] = gitlab.requests
    assert (note["path"], note["token"]) == ("/api/v4/projects/42/merge_requests/5/notes", TOKEN)
    assert note["body"] == {"body": review(base)}
    assert done.stdout == review(base) + "\n"


def test_github_gets_the_review_as_a_comment(tmp_path: Path, github: FakeGitHub) -> None:  # noqa: F811
    top, base = definitions(tmp_path)
    event = write(tmp_path / "event.json", json.dumps({"pull_request": {"number": 5, "base": {"sha": base}}}))
    done = mpc("ci", "review", "pipeline.yml", cwd=top, cache=tmp_path / "cache", environ={
        **NO_CI, "GITHUB_EVENT_NAME": "pull_request", "GITHUB_EVENT_PATH": str(event),
        "GITHUB_REPOSITORY": "acme/defs"})
    assert done.returncode == 0, done.stderr
    [post] = github.requests
    assert (post["method"], post["path"]) == ("POST", "/repos/acme/defs/issues/5/comments")
    assert post["body"] == {"body": review(base)}


def test_outside_a_merge_request_nothing_is_done(tmp_path: Path) -> None:
    top, _ = definitions(tmp_path)
    done = mpc("ci", "review", "pipeline.yml", cwd=top, cache=tmp_path / "cache", environ=NO_CI)
    assert (done.returncode, done.stdout) == (0, "")
    assert done.stderr == ("mpc ci review: not in a merge request's pipeline (and no --base): "
                           "nothing to review\n")
    done = mpc("ci", "review", "pipeline.yml", "--base", "HEAD~1", cwd=top, cache=tmp_path / "cache",
               environ=NO_CI)
    assert done.returncode == 0 and "- joint `shoulder`: limit lower -2.5 → -1" in done.stdout


def test_gitlab_without_a_token_is_not_posted(tmp_path: Path) -> None:
    top, base = definitions(tmp_path)
    done = mpc("ci", "review", "pipeline.yml", cwd=top, cache=tmp_path / "cache", environ={
        **NO_CI, "CI_MERGE_REQUEST_IID": "5", "CI_API_V4_URL": "http://127.0.0.1:9/api/v4",
        "CI_MERGE_REQUEST_PROJECT_ID": "42", "CI_MERGE_REQUEST_DIFF_BASE_SHA": base})
    assert done.returncode == 1
    assert done.stderr == ("mpc ci review: error: the review was not posted: no token to post with: set "
                           "MPC_GITLAB_TOKEN (a project access token that may write notes)\n")
