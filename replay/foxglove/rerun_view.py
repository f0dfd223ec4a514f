"""A run's log in Rerun's viewer with a ready layout: ``replay rerun LOG [--web] [--port N]``
(docs/foxglove.md, "Rerun"). Needs the optional extra: ``pip install 'paper-replay[rerun]'``.

Converts the log with ``rerun mcap convert`` (``NAME.rrd``) on a *duration* timeline, so that
Rerun's time axis reads the run's simulated seconds (not dates in 1970); writes a blueprint
(``NAME.rbl``: a 3-D view in the ``world`` frame, each camera's images, the /log lines) and opens
both in Rerun's viewer: native, or with ``--web`` its web viewer served on 127.0.0.1. Both files
go in a private temporary folder, removed at the end (nothing is written beside the log). The
viewer runs in a process group of its own, and every process of that group (the web server and
whatever it started) is stopped when the command ends: closed, Ctrl-C, SIGTERM or SIGHUP.
``--shot FILE`` (with ``--web``) screenshots the web viewer with Debian's chromium (Playwright,
shared/BROWSER-TESTS.md), FILE checked as any output (a new file or an earlier PNG, never a
link); ``--at T`` converts the log only up to T seconds.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Iterator
from urllib.parse import quote

APP_ID = "paper-replay"
EXTRA = "pip install 'paper-replay[rerun]'"
RRD_MAGIC = b"RRF2"  # what a Rerun recording or blueprint starts with
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
# what ends the command as Ctrl-C does: `kill`, `timeout`, a closed terminal
STOP_SIGNALS = (signal.SIGTERM, *([signal.SIGHUP] if hasattr(signal, "SIGHUP") else []))
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
    """The ``rerun`` executable of rerun-sdk: its binary itself (the ``rerun`` script runs it as
    a child of its own, which would outlive a ``kill -9`` of this command: see
    :func:`_die_with_parent`), else the script beside this Python or on PATH; RerunError if
    absent."""
    try:
        import rerun  # noqa: F401
    except ImportError:
        raise RerunError(f"Rerun is not installed: {EXTRA}") from None
    with contextlib.suppress(ImportError):
        import rerun_cli

        binary = Path(rerun_cli.__file__).with_name("rerun")  # (where its script finds it)
        if "RERUN_CLI_PATH" not in os.environ and os.access(binary, os.X_OK):
            return str(binary)
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


def _output(log: Path, folder: Path | None, suffix: str) -> Path:
    """``folder/NAME.SUFFIX``; with no folder, beside the log, checked as any output (a new
    file or an earlier Rerun file, never a link)."""
    path = (folder / log.name if folder else log).with_suffix(suffix)
    if folder is None:
        from replay.log import LogError
        from replay.log.output import check_output

        try:
            check_output(path, kind="Rerun file", magic=RRD_MAGIC)
        except LogError as exc:
            raise RerunError(str(exc)) from None
    return path


def convert(log: Path, at: float | None = None, folder: Path | None = None) -> Path:
    rrd = _output(log, folder, ".rrd")
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


def blueprint(log: Path, folder: Path | None = None) -> Path:
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
    rbl = _output(log, folder, ".rbl")
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
def running(
    cmd: list[str], quiet: bool = True, grace: float = STOP_GRACE
) -> Iterator[subprocess.Popen]:
    """``cmd`` in a process group of its own, stopped with all it started on leaving (what
    ignores SIGTERM killed after ``grace`` seconds)."""
    out = subprocess.DEVNULL if quiet else None
    proc = subprocess.Popen(
        cmd, stdout=out, stderr=out, start_new_session=True, preexec_fn=_die_with_parent()
    )
    try:
        yield proc
    finally:
        held = {signal.SIGINT, *STOP_SIGNALS}
        old = signal.pthread_sigmask(signal.SIG_BLOCK, held)  # (none interrupts the stop)
        try:
            stop_group(proc, grace)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _die_with_parent():
    """On Linux, a function for the child (``preexec_fn``) that has the kernel send it SIGTERM
    when this process dies, ``kill -9`` included (``prctl(PR_SET_PDEATHSIG)``); else None."""
    if not sys.platform.startswith("linux"):
        return None
    import ctypes

    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None
    parent = os.getpid()

    def child() -> None:
        prctl(1, int(signal.SIGTERM), 0, 0, 0)  # PR_SET_PDEATHSIG
        if os.getppid() != parent:  # (died before that: nobody will send it)
            os._exit(1)

    return child


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
        png = page.screenshot(timeout=180_000)
        browser.close()
    from replay.log.output import write_output

    write_output(out, lambda tmp: tmp.write_bytes(png))  # (never through a link)


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
    """Convert ``log``, write its blueprint (both in a private temporary folder), and show them
    until the viewer (or Ctrl-C, SIGTERM, SIGHUP) ends; then the viewer's processes are stopped
    and the folder removed. SIGTERM and SIGHUP end the command with 128 + the signal's number."""
    if shot is not None and not web:
        raise RerunError("--shot needs --web")
    if shot is not None:  # (before anything starts)
        from replay.log import LogError
        from replay.log.output import check_output

        try:
            check_output(shot, kind="screenshot", magic=PNG_MAGIC)
        except LogError as exc:
            raise RerunError(str(exc)) from None
    waiting = False
    with _signals_as_interrupt() as came, tempfile.TemporaryDirectory(prefix="replay-rerun-") as d:
        try:
            rrd, rbl = convert(log, at, Path(d)), blueprint(log, Path(d))
            with running(viewer_command(rrd, rbl, web, port), quiet=web) as proc:
                if shot is not None:
                    time.sleep(2.0)
                    screenshot(web_url(port), shot, wait)
                    echo(str(shot))
                    return
                if web:
                    echo(web_url(port))
                waiting = True
                proc.wait()
        except KeyboardInterrupt:
            if not (came or waiting):
                raise
            # (Ctrl-C while the viewer shows: it closed, as its own window's close would)
    if came:
        raise SystemExit(128 + came[0])


@contextlib.contextmanager
def _signals_as_interrupt() -> Iterator[list[int]]:
    """SIGTERM and SIGHUP (``kill``, ``timeout``, a closed terminal) take Ctrl-C's path: the
    viewer's process group is stopped, the temporary folder removed. Yields the signals that
    came (in the main thread only; elsewhere Python cannot handle signals)."""
    came: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield came
        return

    def handler(signum, frame) -> None:
        came.append(signum)
        if len(came) == 1:  # (a second one while the first is handled: the same stop)
            raise KeyboardInterrupt

    old = {sig: signal.signal(sig, handler) for sig in STOP_SIGNALS}
    try:
        yield came
    finally:
        for sig, h in old.items():
            signal.signal(sig, h)
