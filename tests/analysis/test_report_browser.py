"""replay report in a real browser: built from the golden logs and the stored ablation tables,
served on 127.0.0.1, opened in Debian's headless Chromium; every figure must load (decoded, not
zero-sized) and every link must resolve (files: HTTP 200; anchors: an element with that id)."""

from __future__ import annotations

import functools
import http.server
import threading
from pathlib import Path

import pytest
from click.testing import CliRunner

import playwright.sync_api as playwright_api  # noqa: E402

from replay.cli import main  # noqa: E402
from chromium import FLAGS, _ensure_chromium  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    import os

    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        r = CliRunner().invoke(main, ["report", "-o", str(out), "--logs", "data/golden"])
    finally:
        os.chdir(cwd)
    assert r.exit_code == 0, r.output
    return out


def test_report_has_every_part(report):
    md = (report / "index.md").read_text()
    for part in (
        "Friction Independent",
        "Direct Mapping",
        "### Claims",
        "### Ablations",
        "stick_friction",
        "catch_rate",
        "## Versions",
        "## Commands",
        "grasp_loops",
        "Grasp rate (k/n with Wilson 95 % intervals)",
        "## Theses",
        "grasp_components",
        "stick_conditions",
        "catch_optimisation",
        "replay ablate",
    ):
        assert part in md, part
    assert len(list((report / "figures").glob("*.png"))) >= 2
    assert len(list((report / "ablations").glob("*.png"))) >= 7


def test_every_figure_and_link_loads_in_chromium(report):
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(report))
    handler.log_message = lambda *a, **k: None
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    try:
        with playwright_api.sync_playwright() as p:
            browser = p.chromium.launch(executable_path=_ensure_chromium(), args=FLAGS)
            try:
                page = browser.new_page()
                page.goto(base + "index.html", wait_until="load")
                images = page.eval_on_selector_all(
                    "img",
                    "els => els.map(e => [e.getAttribute('src'), e.complete, "
                    "e.naturalWidth, e.naturalHeight])",
                )
                assert len(images) >= 8
                broken = [src for src, done, w, h in images if not (done and w > 100 and h > 100)]
                assert not broken, f"figures that did not load: {broken}"
                links = page.eval_on_selector_all(
                    "a", "els => els.map(e => e.getAttribute('href'))"
                )
                assert len(links) >= 10
                bad = []
                for href in links:
                    if href.startswith("#"):
                        if page.query_selector(f"[id='{href[1:]}']") is None:
                            bad.append(href)
                        continue
                    resp = page.request.get(base + href)
                    if resp.status != 200 or not resp.body():
                        bad.append(f"{href} ({resp.status})")
                assert not bad, f"links that do not resolve: {bad}"
            finally:
                browser.close()
    finally:
        server.shutdown()
        server.server_close()
