"""A report built from hostile logs (issue #36, item 3), opened in Debian's headless Chromium over
http and from file://: no payload runs. Each payload would set the page's title, open a dialog
or request a beacon server on 127.0.0.1; the test asserts none did, while the hostile runs'
figures (their file names made safe) still load."""

from __future__ import annotations

import functools
import http.server
import threading
from pathlib import Path

import pytest
from click.testing import CliRunner

import playwright.sync_api as playwright_api  # noqa: E402

from chromium import FLAGS, _ensure_chromium  # noqa: E402
from replay.cli import main  # noqa: E402
from replay.log import LogReader, LogWriter  # noqa: E402
from replay.messages import TOPIC_SCENARIO  # noqa: E402

TITLE = "paper-replay: reproduction report"


def _payloads(beacon: str) -> list[dict]:
    """(name, seed) of each forged log: every way out of the markup the report writes."""
    js = "document.title='PWNED';alert(1);fetch('{}/{}')"
    return [
        {  # the viewer payload, in the report
            "name": 'run<iframe style=display:none srcdoc="<script>parent.'
            + js.format(beacon, "iframe")
            + '</script>"></iframe>',
            "seed": "<script>" + js.format(beacon, "seed") + "</script>",
        },
        {"name": "x' onerror='" + js.format(beacon, "quote1").replace("'", '"') + "' y", "seed": 1},
        {
            "name": 'y" onerror="' + js.format(beacon, "quote2") + '" z',
            "seed": f"<img src={beacon}/img onerror=alert(2)>",
        },
        {"name": f"<svg onload=\"fetch('{beacon}/svg')\">", "seed": {"k": "<b>a dict</b>"}},
        {"name": f"javascript:fetch('{beacon}/js')", "seed": "<style>img{display:none}</style>"},
        {
            "name": f"../../<base href={beacon}/>",
            "seed": f"<meta http-equiv=refresh content=0;{beacon}>",
        },
    ]


class _Beacon(http.server.BaseHTTPRequestHandler):
    hits: list[str] = []

    def do_GET(self):  # noqa: N802
        self.hits.append(self.path)
        self.send_response(204)
        self.end_headers()

    def log_message(self, *args):
        pass


def _serve(handler) -> http.server.ThreadingHTTPServer:
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


@pytest.fixture(scope="module")
def beacon():
    _Beacon.hits = []
    server = _serve(_Beacon)
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}", _Beacon.hits
    finally:
        server.shutdown()
        server.server_close()


@pytest.fixture(scope="module")
def report(tmp_path_factory, beacon) -> Path:
    root = tmp_path_factory.mktemp("hostile_browser")
    base = root / "base.mcap"
    r = CliRunner().invoke(main, ["run", "stick_3step", "-q", "-o", str(base)])
    assert r.exit_code == 0, r.output
    logs = root / "logs"
    logs.mkdir()
    for i, fields in enumerate(_payloads(beacon[0])):
        with LogWriter(logs / f"{i}.mcap") as w:
            for m in LogReader(base).messages():
                data = dict(m.data, **fields) if m.topic == TOPIC_SCENARIO else m.data
                w.write(m.topic, data, m.t_ns)
    r = CliRunner().invoke(main, ["report", "-o", str(root / "report"), "--logs", str(logs)])
    assert r.exit_code == 0, r.output
    return root / "report"


@pytest.mark.parametrize("scheme", ["http", "file"])
def test_no_payload_runs_in_chromium(report, beacon, scheme):
    url, hits = beacon
    server = None
    if scheme == "http":
        handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(report))
        handler.log_message = lambda *a, **k: None
        server = _serve(handler)
        page_url = f"http://127.0.0.1:{server.server_address[1]}/index.html"
    else:
        page_url = (report / "index.html").as_uri()
    dialogs: list[str] = []
    try:
        with playwright_api.sync_playwright() as p:
            browser = p.chromium.launch(executable_path=_ensure_chromium(), args=FLAGS)
            try:
                page = browser.new_page()
                page.on("dialog", lambda d: (dialogs.append(d.message), d.dismiss()))
                page.goto(page_url, wait_until="load", timeout=30_000)
                page.wait_for_timeout(500)  # (time for an onerror, a fetch, a refresh)
                assert page.title() == TITLE and page.url == page_url
                images = page.eval_on_selector_all(
                    "img", "els => els.map(e => [e.getAttribute('src'), e.naturalWidth])"
                )
                figures = [(src, w) for src, w in images if src.startswith("figures/")]
                assert len(figures) == len(_payloads(url)), images  # each run's Fig. 7
                assert all(w > 100 for _, w in figures), figures  # loaded, names made safe
                tags = page.eval_on_selector_all(
                    "iframe, script, svg, base, meta, style", "e => e.length"
                )
                assert tags == 3, tags  # the report's own two <meta> and its <style>
                # the beacon hears a request the harness makes: silence below means something
                assert page.request.get(f"{url}/harness").status == 204
            finally:
                browser.close()
    finally:
        if server is not None:
            server.shutdown()
            server.server_close()
    assert hits == ["/harness"], hits
    hits.clear()
    assert dialogs == []
