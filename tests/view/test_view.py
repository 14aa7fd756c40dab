"""`mpc view`: the viewer of UR5's definition, loaded in headless Chromium. The robot is drawn,
a joint slider moved through the page moves it, and the page loads nothing but from the
viewer's own loopback address."""

from __future__ import annotations

import io
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tests.conftest import ERD, definition, write
from tests.view.chromium import Browser

UR5 = ERD / "ur_description/urdf/ur5_robot.urdf"


def start_view(tmp_path: Path, *args: str) -> tuple[subprocess.Popen, str]:
    """`mpc view …` in a process of its own; it and the URL it printed."""
    env = {**os.environ, "MPC_CACHE_DIR": str(tmp_path / "cache")}
    process = subprocess.Popen([sys.executable, "-m", "mpc.cli.main", "view", *args, "--port", "0"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    assert process.stdout is not None
    for line in process.stdout:  # ends when the process does
        found = re.match(r"mpc view: (http://127\.0\.0\.1:\d+/)  \(Ctrl-C ends it\)$", line.strip())
        if found:
            return process, found.group(1)
    raise AssertionError(f"mpc view printed no URL: {process.stderr.read() if process.stderr else ''}")


def viewport(png: bytes) -> np.ndarray:
    """The 3D part of a screenshot: left of the GUI panel, below the notifications."""
    picture = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    return picture[160:, :540]


def robot_pixels(picture: np.ndarray) -> int:
    """Pixels of the grey robot (not the white background, not the coloured axes gizmo)."""
    spread = picture.max(axis=2) - picture.min(axis=2)
    return int(np.sum((spread < 20) & (picture.max(axis=2) < 225)))


def settled(browser: Browser, before: np.ndarray | None = None, seconds: float = 90) -> np.ndarray:
    """A screenshot once the drawing stops changing (and differs from `before`, when given)."""
    deadline, last = time.monotonic() + seconds, None
    while time.monotonic() < deadline:
        time.sleep(0.5)
        now = viewport(browser.screenshot())
        if last is not None and np.array_equal(now, last) and robot_pixels(now) > 500 and (
                before is None or not np.array_equal(now, before)):
            return now
        last = now
    raise AssertionError("the page's drawing did not settle")


@pytest.mark.long
def test_view_draws_the_robot_and_a_slider_moves_it(tmp_path: Path) -> None:
    text = definition(UR5, robotname="ur5") + "  poses:\n    up:\n      shoulder_lift_joint: -1.2\n"
    path = write(tmp_path / "ur5.yml", text)
    process, url = start_view(tmp_path, str(path))
    browser = Browser(tmp_path / "profile")
    try:
        browser.call("Network.enable")
        browser.call("Page.navigate", url=url)
        browser.wait_for("document.querySelectorAll('[role=slider]').length === 6")
        labels = browser.evaluate("document.body.innerText")
        for text in ("Visual", "Collision", "Link frames", "Compare model (ghost)", "Pose",
                     "shoulder_lift_joint", "elbow_joint", "wrist_3_joint"):
            assert text in labels
        first = settled(browser)
        Image.fromarray(first.astype(np.uint8)).save(tmp_path / "first.png")
        assert robot_pixels(first) > 2000  # the robot is drawn, not a speck

        # Move shoulder_lift_joint through the page: focus its slider, press the right arrow key
        # 16 times (a step is 1/200 of its range, UR5's ±2π: 0.063 rad).
        assert browser.evaluate("(() => { const s = document.querySelectorAll('[role=slider]')[1];"
                                " s.focus(); return document.activeElement === s; })()")
        browser.press("ArrowRight", "ArrowRight", 39, times=16)
        value = browser.wait_for("(() => { const s = document.querySelectorAll('[role=slider]')[1];"
                                 " const v = Number(s.getAttribute('aria-valuenow'));"
                                 " return v > 0.9 && v; })()")
        assert abs(float(value) - 16 * 4 * np.pi / 200) < 0.01
        moved = settled(browser, before=first)
        Image.fromarray(moved.astype(np.uint8)).save(tmp_path / "moved.png")
        changed = np.any(np.abs(moved - first) > 30, axis=2)
        assert changed.mean() > 0.01, "the picture did not change"

        requested = [e["params"]["request"]["url"] for e in browser.events
                     if e.get("method") == "Network.requestWillBeSent"]
        local = (url, "data:", "blob:" + url.rstrip("/"))
        assert requested and all(u.startswith(local) for u in requested), [u[:80] for u in requested]
    finally:
        browser.close()
        process.send_signal(signal.SIGINT)
        process.wait(timeout=30)
