"""The test protocol's pictures in a deployment: committed with the model, and linked in the
merge request's description by the forge's raw address of the pushed commit."""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from mpc.core.diagnostics import Sink
from mpc.deploy import deploy_model
from mpc.deploy.pictures import raw_base, web_address
from tests.conftest import Diags
from tests.deploy.conftest import Model, Server, git

PROTOCOL = """\
## Model tests of `arm-model`: **passed** (1 passed, 0 failed)

| view | release | new | overlay |
|---|---|---|---|
| iso | ![iso, release](test_pictures/iso_release.png) | ![iso, new](test_pictures/iso_new.png) \
| ![iso, overlay](test_pictures/iso_overlay.png) |

Also see [the docs](docs/x.png).
"""


def pictures(folder: Path) -> dict[str, bytes]:
    """Three small real PNGs beside a protocol, as mpc test writes them."""
    (folder / "test_pictures").mkdir(parents=True)
    out = {}
    for i, side in enumerate(("release", "new", "overlay")):
        buf = io.BytesIO()
        Image.fromarray(np.full((8, 8, 3), 60 * i, dtype=np.uint8)).save(buf, format="PNG")
        out[f"test_pictures/iso_{side}.png"] = buf.getvalue()
        (folder / f"test_pictures/iso_{side}.png").write_bytes(buf.getvalue())
    (folder / "test_protocol.md").write_text(PROTOCOL)
    return out


def forge_address(server: Server, host: str) -> str:
    """`https://<host>/acme/arm-model.git`, which git reaches as the bare repository on disk."""
    with open(os.environ["GIT_CONFIG_GLOBAL"], "a") as config:
        config.write(f'[url "{server.path.parent.parent}/"]\n\tinsteadOf = https://{host}/\n')
    return f"https://{host}/acme/arm-model.git"


def test_pictures_are_committed_and_linked_to_the_pushed_commit(model: Model, server: Server,
                                                                tmp_path: Path) -> None:
    program = model.compile()
    written = pictures(tmp_path / "tested")
    remote = forge_address(server, "gitlab.example.org")
    sink = Sink()
    result = deploy_model(program, model.built, model.settings(remote=remote), sink,
                          protocol_markdown=PROTOCOL, pictures=tmp_path / "tested" / "test_pictures")
    assert sink.diagnostics == [] and result.ok and result.pushed and result.commit
    for path, data in written.items():  # committed with the model, byte for byte
        blob = git(server.path, "rev-parse", f"{result.commit}:{path}")
        assert blob == git(tmp_path, "hash-object", str(tmp_path / "tested" / path))
        assert (tmp_path / "tested" / path).read_bytes() == data
    [push] = server.pushes()
    description = next(o for o in push["options"] if o.startswith("merge_request.description="))
    raw = f"https://gitlab.example.org/acme/arm-model/-/raw/{result.commit}/"
    for side in ("release", "new", "overlay"):
        assert f"![iso, {side}]({raw}test_pictures/iso_{side}.png)" in description
    assert "](test_pictures/" not in description
    assert "[the docs](docs/x.png)" in description  # not a picture of mpc's: left alone
    assert result.merge_request is not None and raw in result.merge_request.description


def test_a_remote_without_web_host_keeps_relative_links(model: Model, server: Server,
                                                        tmp_path: Path) -> None:
    program = model.compile()
    pictures(tmp_path / "tested")
    result = deploy_model(program, model.built, model.settings(remote=server.url), Sink(),
                          protocol_markdown=PROTOCOL, pictures=tmp_path / "tested" / "test_pictures")
    assert result.pushed and "test_pictures/iso_new.png" in server.files()
    [push] = server.pushes()
    description = next(o for o in push["options"] if o.startswith("merge_request.description="))
    assert "](test_pictures/iso_new.png)" in description
    assert "(The pictures are in the commit's `test_pictures/`; the repository's address names no " \
           "web host to link them.)" in description


def test_a_linked_picture_is_refused(model: Model, server: Server, tmp_path: Path, diags: Diags) -> None:
    program = model.compile()
    pictures(tmp_path / "tested")
    secret = tmp_path / "secret.png"
    secret.write_bytes(b"not for the forge")
    (tmp_path / "tested/test_pictures/iso_new.png").unlink()
    (tmp_path / "tested/test_pictures/iso_new.png").symlink_to(secret)
    result = deploy_model(program, model.built, model.settings(remote=server.url), diags,
                          protocol_markdown=PROTOCOL, pictures=tmp_path / "tested" / "test_pictures")
    assert not result.ok and server.branches() == {}
    assert diags.take_error("E0850").message.startswith("the test picture ")


@pytest.mark.parametrize(("remote", "forge", "base"), [
    ("git@github.com:acme/arm-model.git", "github", "https://github.com/acme/arm-model/raw/abc/"),
    ("https://ci:secret@gitlab.example.org/group/sub/arm.git", "gitlab",
     "https://gitlab.example.org/group/sub/arm/-/raw/abc/"),
    ("ssh://git@gitlab.example.org:2222/group/arm.git", "gitlab",
     "https://gitlab.example.org/group/arm/-/raw/abc/"),
    ("/srv/git/arm.git", "gitlab", None),
    ("file:///srv/git/arm.git", "github", None),
])
def test_raw_addresses(remote: str, forge: str, base: str | None) -> None:
    assert raw_base(forge, remote, "abc") == base
    assert (web_address(remote) is None) == (base is None)
