"""The replay viewer in a real browser: Debian's headless Chromium driven by Playwright.

For each log (synthetic air-table and arm logs written here; a ``data/golden/*.mcap`` of each scene
that draws differently; and
any listed in ``PAPER_REPLAY_VIEWER_LOGS``, ``:``-separated): serve it on 127.0.0.1, open the
page, wait for the 3-D scene to be drawn (screenshots polled against a deadline), move the time
slider through its number box to two positions, and check that the canvas is drawn and that the
scene changed between them. Servers stop by themselves (watchdog), browsers are closed.

``PAPER_REPLAY_SCREENSHOTS=docs/img`` keeps the second screenshot of each as
``viewer_NAME.png`` (that is how the pictures in docs/viewer.md are made).
"""

from __future__ import annotations

import io
import os
import shutil
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import playwright.sync_api as playwright_api  # noqa: E402
from PIL import Image  # noqa: E402

from replay import registry  # noqa: E402
from replay.log import LogReader  # noqa: E402
from replay.viewer import Viewer  # noqa: E402
from synthetic_logs import write_arm_log, write_stick_log  # noqa: E402
from chromium import FLAGS, _ensure_chromium  # noqa: E402
from grasp_synthetic import write_grasp_log  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
VIEWPORT = {"width": 1280, "height": 800}
# the 3-D canvas without the GUI panel (right) and the software-WebGL toast (top left)
SCENE = (slice(170, 780), slice(330, 930))
SERVER_LIFETIME = 420.0  # s: the watchdog stops a server left running by a failed test
SHOT_TIMEOUT = 90_000  # ms: software WebGL on a loaded 2-core machine can take ~60 s a frame
PAGE_DEADLINE = 300.0  # s: for the whole page (first frame, two slider moves)


@pytest.fixture(scope="module")
def browser():
    exe = _ensure_chromium()
    with playwright_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=exe, args=FLAGS)
        yield b
        b.close()


def _cases() -> list[tuple[str, object]]:
    """(name, tmp_dir -> log paths): synthetic logs made in the test, then golden/given ones."""
    cases = [
        ("stick", lambda d: [write_stick_log(d / "stick.mcap")]),
        ("catch", lambda d: [write_arm_log(d / "catch.mcap")]),
        (
            "grasp",
            lambda d: [
                write_arm_log(
                    d / "grasp.mcap", name="synthetic_grasp", arm="wam7", hand="grasp4", obj="box"
                )
            ],
        ),
        ("grasp_scene", lambda d: [write_grasp_log(d / "grasp_scene.mcap", duration=1.2)]),
        (
            "overlay",
            lambda d: [
                write_stick_log(d / "a.mcap", name="spin_4"),
                write_stick_log(d / "b.mcap", name="spin_9", spin=9.0),
            ],
        ),
    ]
    extra = _one_golden_per_drawing()
    extra += [Path(p) for p in os.environ.get("PAPER_REPLAY_VIEWER_LOGS", "").split(":") if p]
    cases += [(p.stem, lambda d, p=p: [p]) for p in extra]
    return cases


def _one_golden_per_drawing() -> list[Path]:
    """The shortest-named golden of each scene that draws differently: an engine's scene that
    only reads its own Params draws as its rig's (every golden is drawn and moved server-side in
    test_viewer.py's ``test_every_golden_is_drawn_and_moves``)."""
    kept: dict[type, Path] = {}
    for path in sorted((ROOT / "data" / "golden").glob("*.mcap"), key=lambda p: (len(p.stem), p)):
        plant = LogReader(path).scenario_config()["plant"]["type"]
        cls = registry.load("viewer_scene", plant)
        kept.setdefault(next(c for c in cls.__mro__ if "build" in vars(c)), path)
    return sorted(kept.values())


def _image(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


def _colours(img: np.ndarray) -> int:
    region = img[SCENE]
    return len(np.unique(region.reshape(-1, 3) // 4, axis=0))


def _changed(a: np.ndarray, b: np.ndarray) -> float:
    """Fraction of scene pixels that differ visibly."""
    d = np.abs(a[SCENE].astype(int) - b[SCENE].astype(int)).max(axis=2)
    return float((d > 24).mean())


def _poll(page, ok, deadline: float, what: str) -> np.ndarray:
    last = None
    while time.monotonic() < deadline:
        last = _image(page.screenshot(timeout=SHOT_TIMEOUT))
        if ok(last):
            return last
        time.sleep(0.4)
    raise AssertionError(f"timed out waiting for {what}")


def _wait_for(cond, deadline: float, what: str) -> None:
    while time.monotonic() < deadline:
        if cond():
            return
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


def _close_toasts(page) -> None:
    """Close the "Software WebGL rendering detected" notice (cosmetic, for the pictures)."""
    try:
        page.locator(".mantine-Notification-closeButton").first.click(timeout=2000)
    except playwright_api.Error:
        pass


def _set_time(page, viewer: Viewer, t: float, deadline: float) -> None:
    box = page.locator("input.mantine-NumberInput-input").first
    box.fill(f"{t:.4f}")
    box.press("Enter")
    box.blur()
    # several key presses can reach the server as fewer updates: check the final value
    _wait_for(lambda: abs(viewer.time - t) < 1e-3, deadline, f"the server to show t = {t}")


def _settled(page, path: Path, deadline: float) -> np.ndarray:
    """The screenshot (kept at ``path``) once two in a row are the same: the moved scene has been
    drawn whole (or the deadline, 3 s at most, has passed)."""
    deadline = min(deadline, time.monotonic() + 3.0)
    last = _image(page.screenshot(timeout=SHOT_TIMEOUT))
    while True:
        img = _image(page.screenshot(path=str(path), timeout=SHOT_TIMEOUT))
        if _changed(img, last) == 0.0 or time.monotonic() > deadline:
            return img
        last = img


def _moved_to(page, viewer: Viewer, ref: np.ndarray, fractions, least: float, deadline: float):
    """Move the slider to the first of ``fractions`` of the run at which the scene differs from
    ``ref`` (more than ``least`` of its pixels); the screenshot there."""
    t0, t1 = viewer.timeline.t0, viewer.timeline.t1
    for k, f in enumerate(fractions):
        last = k == len(fractions) - 1
        # (an earlier position where nothing in view moves yet, e.g. a catch before the ball is
        # seen, is given up after 8 s: the next one is tried with the rest of the deadline)
        share = deadline if last else min(deadline, time.monotonic() + 8.0)
        _set_time(page, viewer, t0 + f * (t1 - t0), deadline)
        try:
            return _poll(
                page, lambda img: _changed(img, ref) > least, share, f"the scene to move (t at {f})"
            )
        except AssertionError:
            if last:
                raise
    raise AssertionError("no slider position to try")


CASES = _cases()


@pytest.mark.parametrize("name,make", CASES, ids=[c[0] for c in CASES])
def test_viewer_draws_and_moves_in_a_browser(browser, name, make, tmp_path):
    viewer = Viewer.open(make(tmp_path), port=0)  # host 127.0.0.1
    watchdog = threading.Timer(SERVER_LIFETIME, viewer.stop)
    watchdog.daemon = True
    watchdog.start()
    page = browser.new_page(viewport=VIEWPORT)
    try:
        assert viewer.url.startswith("http://127.0.0.1:")
        page.goto(viewer.url)
        deadline = time.monotonic() + PAGE_DEADLINE
        first = _poll(page, lambda img: _colours(img) > 60, deadline, "the scene to be drawn")
        _close_toasts(page)
        # the view is fitted to the moving parts (the hand, the object near it): in a catch log
        # the arm waits still until the ball is seen (0.1 s of 0.3), so mid-run comes first
        # (0.15 there waited out its 8 s), and where nothing in view moves, the next is tried
        _moved_to(page, viewer, first, (0.5, 0.15, 0.75), 0.0005, deadline)
        a = _settled(page, tmp_path / f"{name}_a.png", deadline)
        _moved_to(page, viewer, a, (0.3, 0.85, 0.95), 0.001, deadline)
        b = _settled(page, tmp_path / f"{name}_b.png", deadline)
        assert _colours(a) > 60 and _colours(b) > 60, "the canvas is not drawn"
        assert _changed(a, b) > 0.001, "the scene did not change between the slider positions"
        keep = os.environ.get("PAPER_REPLAY_SCREENSHOTS")
        if keep:
            Path(keep).mkdir(parents=True, exist_ok=True)
            shutil.copy(tmp_path / f"{name}_b.png", Path(keep) / f"viewer_{name}.png")
    finally:
        page.close()
        watchdog.cancel()
        viewer.stop()
