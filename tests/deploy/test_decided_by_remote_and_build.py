"""`mpc deploy` decides by the remote and the build, not by its work folder (issue 29, 18):
the success branch is the remote's HEAD branch on every run, also after a failed deploy left
its clone on the failure branch; a build whose protocol failed goes to the failure branch
with `Tests: failed (…)`, one whose protocol passed to the success branch."""

from __future__ import annotations

from pathlib import Path

from mpc.checks.protocol import Protocol, failed, passed
from mpc.core.diagnostics import Severity, Sink
from mpc.deploy import deploy_model
from tests.deploy.conftest import Model, Server, git, heavier
from tests.mpc_command import mpc


def write_protocol(folder: Path, ok: bool) -> Protocol:
    """The protocol `mpc test` writes (checks/protocol.py), into the build folder."""
    protocol = Protocol(model="arm-model")
    protocol.add(passed("total_mass", "2.5 kg"))
    protocol.add(passed("compare_com") if ok else failed("compare_com", "the COM moved by 0.2 m"))
    protocol.write(folder)
    return protocol


def messages(sink: Sink) -> list[str]:
    """The messages of the errors, each E0860."""
    assert all(d.code == "E0860" for d in sink.diagnostics if d.severity is Severity.ERROR)
    return [d.message for d in sink.diagnostics if d.severity is Severity.ERROR]


def test_after_a_failed_first_deploy_the_success_branch_is_still_the_remotes_head(
        model: Model, server: Server) -> None:
    settings = model.settings(remote=server.url, forge="none")
    bad = deploy_model(model.compile(heavier()), model.built, settings, Sink(), tests_failed=True)
    assert (bad.branch, list(server.branches())) == ("tests-failed", ["tests-failed"])
    # The clone in the work folder is left on the failure branch; the remote's HEAD is unborn.
    assert git(settings.workdir / "arm-model", "symbolic-ref", "HEAD") == "refs/heads/tests-failed"
    good = deploy_model(model.compile(), model.built, settings, Sink())
    assert (good.branch, good.pushed) == ("master", True)
    assert server.branches() == {"tests-failed": bad.commit, "master": good.commit}


def test_the_success_branch_is_the_one_the_empty_remotes_head_names(model: Model, server: Server) -> None:
    git(server.path, "symbolic-ref", "HEAD", "refs/heads/main")
    settings = model.settings(remote=server.url, forge="none")
    deploy_model(model.compile(heavier()), model.built, settings, Sink(), tests_failed=True)
    good = deploy_model(model.compile(), model.built, settings, Sink())
    assert good.branch == "main" and sorted(server.branches()) == ["main", "tests-failed"]


def test_a_build_with_a_failed_protocol_goes_to_the_failure_branch(model: Model, server: Server) -> None:
    settings = model.settings(remote=server.url)
    good = deploy_model(model.compile(), model.built, settings, Sink())
    program = model.compile(heavier())
    protocol = write_protocol(model.built, ok=False)
    sink = Sink()
    bad = deploy_model(program, model.built, settings, sink)  # no protocol, no tests_failed given
    assert sink.diagnostics == [] and bad.ok
    assert (bad.branch, bad.pushed) == ("tests-failed", True)
    assert server.branches() == {"master": good.commit, "tests-failed": bad.commit}
    assert "\nTests: failed (1 passed, 1 failed)\n" in server.message("tests-failed")
    options = server.pushes()[-1]["options"]
    assert options[1] == "merge_request.target=develop"  # the definition's mr_target_branch
    assert protocol.markdown().strip().replace("\n", "<br/>") in options[3]


def test_a_build_with_a_passed_protocol_goes_to_the_success_branch(model: Model, server: Server) -> None:
    program = model.compile()
    write_protocol(model.built, ok=True)
    result = deploy_model(program, model.built, model.settings(remote=server.url, forge="none"), Sink())
    assert result.branch == "master" and list(server.branches()) == ["master"]
    assert "\nTests: passed (2 passed, 0 failed)\n" in server.message("master")


def test_a_build_without_a_protocol_is_not_run(model: Model, server: Server) -> None:
    program = model.compile()
    deploy_model(program, model.built, model.settings(remote=server.url, forge="none"), Sink())
    assert "\nTests: not run\n" in server.message("master")


def test_a_broken_protocol_in_the_build_deploys_nothing(model: Model, server: Server) -> None:
    program = model.compile()
    (model.built / "test_protocol.json").write_text('{"failed": "no", "counts": {}}\n')
    sink = Sink()
    result = deploy_model(program, model.built, model.settings(remote=server.url, forge="none"), sink)
    assert not result.ok and server.branches() == {} and server.pushes() == []
    assert messages(sink) == [(
        f"the build's test protocol '{model.built}/test_protocol.json' is not one that `mpc test` writes: "
        "it needs `failed` (true or false) and `counts` of passed, failed, waived and skipped tests")]
    (model.built / "test_protocol.json").write_text("{not json")
    sink = Sink()
    deploy_model(program, model.built, model.settings(remote=server.url, forge="none"), sink)
    [message] = messages(sink)
    assert message.startswith(f"the build's test protocol '{model.built}/test_protocol.json' is not JSON: ")
    assert server.pushes() == []


def test_mpc_deploy_sends_a_failed_protocol_to_the_failure_branch(model: Model, server: Server,
                                                                  tmp_path: Path) -> None:
    model.compile()
    write_protocol(tmp_path / "tested", ok=False)  # --protocol elsewhere, without --tests-failed
    run = mpc("deploy", model.definition, "--built", model.built, "--remote", server.url,
              "--protocol", tmp_path / "tested/test_protocol.md", "--workdir", tmp_path / "work")
    assert run.returncode == 0, run.stderr
    head = git(server.path, "rev-parse", "tests-failed")
    where = f"branch 'tests-failed' of '{server.url}'"
    assert run.stdout == f"deployed 'arm-model' to {where}: commit {head[:12]}\n"
    assert "\nTests: failed (1 passed, 1 failed)\n" in server.message("tests-failed")
