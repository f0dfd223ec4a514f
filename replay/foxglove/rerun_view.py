"""A run's log in Rerun's viewer with a ready layout: ``replay rerun LOG [--web] [--port N]``
(docs/foxglove.md, "Rerun"). Needs the optional extra: ``pip install 'paper-replay[rerun]'``.

Converts the log with ``rerun mcap convert`` (next to it, ``NAME.rrd``) on a *duration*
timeline, so that Rerun's time axis reads the run's simulated seconds (not dates in 1970);
writes a blueprint (``NAME.rbl``: a 3-D view in the ``world`` frame, each camera's images, the
/log lines) and opens both in Rerun's viewer: native, or with ``--web`` its web viewer served on
127.0.0.1. The viewer runs in a process group of its own, and every process of that group (the
web server and whatever it started) is stopped when the command ends, however it ends.
``--shot FILE`` (with ``--web``) screenshots the web viewer with Debian's chromium (Playwright,
shared/BROWSER-TESTS.md); ``--at T`` converts the log only up to T seconds.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Iterator
from urllib.parse import quote

APP_ID = "paper-replay"
EXTRA = "pip install 'paper-replay[rerun]'"
STOP_GRACE = 5.0  # s between SIGTERM and SIGKILL of the viewer's process group
CHROMIUM_FLAGS = [
    "--headless=new",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
]


class RerunError(Exception):
    """One line for the user (the extra missing, a conversion that failed)."""


def rerun_cli() -> str:
    """The ``rerun`` executable of rerun-sdk (beside this Python first); RerunError if absent."""
    try:
        import rerun  # noqa: F401
    except ImportError:
        raise RerunError(f"Rerun is not installed: {EXTRA}") from None
    local = Path(sys.executable).with_name("rerun")
    found = str(local) if local.exists() else shutil.which("rerun")
    if not found:
        raise RerunError(f"rerun-sdk has no 'rerun' executable on PATH: {EXTRA}")
    return found


def convert_command(log: Path, rrd: Path, at: float | None = None) -> list[str]:
    cmd = [rerun_cli(), "mcap", "convert", str(log), "-o", str(rrd)]
    cmd += ["--application-id", APP_ID, "--timeline-type", "duration"]  # simulated seconds
    if at is not None:
        cmd += ["--end-time", f"{int(round(at * 1e9)) + 1}ns"]
    return cmd


def convert(log: Path, at: float | None = None) -> Path:
    rrd = log.with_suffix(".rrd")
    r = subprocess.run(convert_command(log, rrd, at), capture_output=True, text=True)
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise RerunError(f"{log}: rerun mcap convert failed: {last}")
    return rrd


def robot_name(log: Path) -> str | None:
    """The URDF's robot name: Rerun's entity of the robot's geometry."""
    from replay.foxglove.schemas import decode_string
    from replay.log import LogReader
    from replay.messages import TOPIC_ROBOT_DESCRIPTION

    for m in LogReader(log).raw(TOPIC_ROBOT_DESCRIPTION):
        urdf = decode_string(m.data)
        start = urdf.find("<robot name=")
        if start >= 0:
            return urdf[start:].split('"')[1]
    return None


def blueprint(log: Path) -> Path:
    import rerun as rr
    import rerun.blueprint as rrb

    from replay.log import LogReader

    cameras = sorted(t for t in LogReader(log).topic_counts() if t.startswith("/camera/"))
    robot = robot_name(log)
    contents = ["+ /**"] + ([f"- /{robot}/collision_geometries/**"] if robot else [])
    bp = rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial3DView(
                origin="/",
                contents=contents,
                name="3-D (world)",
                spatial_information=rrb.SpatialInformation(
                    target_frame="world", axes=rr.components.ViewCoordinates.RIGHT_HAND_Z_UP
                ),
                eye_controls=rrb.EyeControls3D(
                    kind=rrb.Eye3DKind.Orbital,
                    position=(1.9, -1.4, 1.1),
                    look_target=(0.75, 0.0, 0.45),
                    eye_up=(0, 0, 1),
                ),
            ),
            rrb.Vertical(
                *[rrb.Spatial2DView(origin=c, name=c) for c in cameras],
                rrb.TextLogView(origin="/log", name="/log"),
            ),
            column_shares=[3, 2],
        ),
        rrb.TimePanel(state="collapsed", play_state="paused"),
        collapse_panels=True,
    )
    rbl = log.with_suffix(".rbl")
    bp.save(APP_ID, str(rbl))
    return rbl


def viewer_command(rrd: Path, rbl: Path, web: bool = False, port: int = 9090) -> list[str]:
    cmd = [rerun_cli(), str(rrd), str(rbl)]
    if web:
        cmd += ["--web-viewer", "--bind", "127.0.0.1", "--web-viewer-port", str(port)]
        cmd += ["--port", str(port + 1), "--renderer", "webgl"]
    return cmd


def web_url(port: int) -> str:
    source = quote(f"rerun+http://127.0.0.1:{port + 1}/proxy", safe="")
    return f"http://127.0.0.1:{port}/?url={source}&renderer=webgl"


def stop_group(proc: subprocess.Popen, grace: float = STOP_GRACE) -> None:
    """Stop every process of ``proc``'s group (it leads one: ``start_new_session``): SIGTERM,
    then SIGKILL after ``grace`` seconds for whatever is left."""
    pgid = proc.pid
    for sig, wait in ((signal.SIGTERM, grace), (signal.SIGKILL, grace)):
        try:
            os.killpg(pgid, sig)
        except ProcessLookupError:
            break
        end = time.monotonic() + wait
        while time.monotonic() < end:
            proc.poll()
            try:
                os.killpg(pgid, 0)  # anyone left in the group?
            except ProcessLookupError:
                break
            time.sleep(0.05)
        else:
            continue
        break
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=grace)


@contextlib.contextmanager
def running(cmd: list[str], quiet: bool = True) -> Iterator[subprocess.Popen]:
    """``cmd`` in a process group of its own, stopped with all it started on leaving."""
    out = subprocess.DEVNULL if quiet else None
    proc = subprocess.Popen(cmd, stdout=out, stderr=out, start_new_session=True)
    try:
        yield proc
    finally:
        stop_group(proc)


def screenshot(url: str, out: Path, wait: float) -> None:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=CHROMIUM_FLAGS)
        page = browser.new_page(viewport={"width": 1400, "height": 800})
        page.goto(url)
        time.sleep(wait)  # the software renderer's first frames take tens of seconds
        # the time cursor near the end of the (cut) recording: a click on the collapsed time
        # strip (x 350-1172 px, y 786 px in this 1400 x 800 viewport)
        for fraction in (0.5, 0.98):  # the first click may only wake the (busy) viewer
            page.mouse.click(350 + fraction * (1172 - 350), 786)
            time.sleep(wait / 4)
        page.screenshot(path=str(out), timeout=180_000)
        browser.close()


def view(
    log: Path,
    *,
    web: bool = False,
    port: int = 9090,
    at: float | None = None,
    shot: Path | None = None,
    wait: float = 40.0,
    echo=print,
) -> None:
    """Convert ``log``, write its blueprint, and show both until the viewer (or Ctrl-C) ends."""
    if shot is not None and not web:
        raise RerunError("--shot needs --web")
    rrd, rbl = convert(log, at), blueprint(log)
    with running(viewer_command(rrd, rbl, web, port), quiet=web) as proc:
        if shot is not None:
            time.sleep(2.0)
            screenshot(web_url(port), shot, wait)
            echo(str(shot))
            return
        if web:
            echo(web_url(port))
        with contextlib.suppress(KeyboardInterrupt):
            proc.wait()
