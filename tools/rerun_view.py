"""Open a run's log in Rerun's viewer with a ready layout (docs/foxglove.md, "Rerun").

    python tools/rerun_view.py out/logs/catch_optimised.mcap [--web] [--port 9090] [--shot FILE]

Converts the log with ``rerun mcap convert`` (next to it, ``NAME.rrd``), writes a blueprint
(``NAME.rbl``: a 3-D view in the ``world`` frame, each camera's images, the /log lines) and
opens both in Rerun's viewer: native, or with ``--web`` its web viewer served on 127.0.0.1.
``--shot FILE`` (with ``--web``) screenshots the web viewer with Debian's chromium (Playwright,
as the browser tests do, shared/BROWSER-TESTS.md); ``--at T`` converts the log only up to T
seconds, so that the paused viewer shows that instant.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import time
from pathlib import Path
from urllib.parse import quote

APP_ID = "paper-replay"
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


def rerun_cli() -> str:
    local = Path(sys.executable).with_name("rerun")
    return str(local) if local.exists() else (shutil.which("rerun") or "rerun")


def convert(log: Path, at: float | None = None) -> Path:
    rrd = log.with_suffix(".rrd")
    cmd = [rerun_cli(), "mcap", "convert", str(log), "-o", str(rrd), "--application-id", APP_ID]
    if at is not None:
        cmd += ["--end-time", f"{int(round(at * 1e9)) + 1}ns"]
    subprocess.run(cmd, check=True, capture_output=True)
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", type=Path)
    ap.add_argument("--web", action="store_true")
    ap.add_argument("--port", type=int, default=9090)
    ap.add_argument("--shot", type=Path)
    ap.add_argument("--at", type=float, help="seconds: the time shown in the screenshot")
    ap.add_argument("--wait", type=float, default=40.0)
    args = ap.parse_args()
    rrd, rbl = convert(args.log, args.at), blueprint(args.log)
    cmd = [rerun_cli(), str(rrd), str(rbl)]
    if not args.web:
        subprocess.run(cmd, check=False)
        return
    grpc = args.port + 1
    cmd += ["--web-viewer", "--bind", "127.0.0.1", "--web-viewer-port", str(args.port)]
    cmd += ["--port", str(grpc), "--renderer", "webgl"]
    server = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    source = quote(f"rerun+http://127.0.0.1:{grpc}/proxy", safe="")
    url = f"http://127.0.0.1:{args.port}/?url={source}&renderer=webgl"
    try:
        if args.shot:
            time.sleep(2.0)
            screenshot(url, args.shot, args.wait)
            print(args.shot)
        else:
            print(url)
            server.wait()
    finally:
        server.terminate()
        server.wait(timeout=10)


if __name__ == "__main__":
    main()
