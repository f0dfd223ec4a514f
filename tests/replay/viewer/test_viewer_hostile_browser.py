"""The viewer against hostile logs and hostile pages, in Debian's headless Chromium (issue #36).

- A log whose name, paper, event kinds and field names are HTML/markdown payloads is opened:
  the page shows them as text, and no payload runs script, loads a URL (a beacon server counts
  requests), opens a dialog or makes an element. Control: the same payload given to Viser's
  markdown unescaped does reach the beacon, so the check can fail.
- A page of another origin (another local port, a ``file://`` page, a DNS-rebinding name)
  opens ``ws://127.0.0.1:VIEWER``: refused, nothing received. Controls: the same script run
  in the viewer's own page connects and receives the scene, and with the check switched off
  the foreign page does too.
"""

from __future__ import annotations

import http.server
import threading
import time
from pathlib import Path

import pytest
import viser

import playwright.sync_api as playwright_api  # noqa: E402

from replay.viewer import Viewer, guard  # noqa: E402
from replay.viewer.markup import clean  # noqa: E402
from synthetic_logs import write_hostile_log  # noqa: E402
from chromium import FLAGS, _ensure_chromium  # noqa: E402

REBIND = "rebind.test"  # a name the browser resolves to 127.0.0.1, as DNS rebinding does
SERVER_LIFETIME = 180.0  # s: the watchdog stops a viewer left running by a failed test
DEADLINE = 60.0  # s: for the page to show the GUI / a websocket to settle
SUBPROTOCOL = f"viser-v{viser.__version__}"

# records whether a websocket to the viewer opened and what it received
WS_SCRIPT = (
    """
(url) => {
  const s = (window.__ws = {open: false, messages: 0, bytes: 0, done: false});
  const ws = new WebSocket(url, [%r]);
  ws.binaryType = "arraybuffer";
  ws.onopen = () => { s.open = true; };
  ws.onmessage = (e) => { s.messages += 1; s.bytes += e.data.byteLength || e.data.length; };
  ws.onerror = () => { s.done = true; };
  ws.onclose = () => { s.done = true; };
  setTimeout(() => { s.done = true; }, 8000);  // a connection that stays open: long enough
}
"""
    % SUBPROTOCOL
)
EVIL_PAGE = "<!doctype html><title>elsewhere</title><script>(%s)(%r)</script>"


class _Beacon(http.server.ThreadingHTTPServer):
    """A second local web server: serves a foreign page at /evil.html and counts every other
    request (a payload that loads a URL hits it)."""

    daemon_threads = True

    def __init__(self) -> None:
        self.hits: list[str] = []
        self.page = ""
        beacon = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_GET(self) -> None:  # noqa: N802
                if self.path.startswith("/evil.html"):
                    body = beacon.page.encode()
                    self.send_response(200)
                    self.send_header("Content-Type", "text/html")
                    self.send_header("Content-Length", str(len(body)))
                    self.end_headers()
                    self.wfile.write(body)
                    return
                beacon.hits.append(self.path)
                self.send_response(204)
                self.end_headers()

            do_POST = do_GET

            def log_message(self, *args) -> None:
                pass

        super().__init__(("127.0.0.1", 0), Handler)
        self.port = self.server_address[1]
        threading.Thread(target=self.serve_forever, daemon=True).start()


@pytest.fixture(scope="module")
def browser():
    exe = _ensure_chromium()
    with playwright_api.sync_playwright() as p:
        b = p.chromium.launch(
            executable_path=exe, args=[*FLAGS, f"--host-resolver-rules=MAP {REBIND} 127.0.0.1"]
        )
        yield b
        b.close()


@pytest.fixture
def beacon():
    b = _Beacon()
    yield b
    b.shutdown()
    b.server_close()


@pytest.fixture
def serve():
    made = []

    def make(paths):
        v = Viewer.open(paths, port=0)  # 127.0.0.1
        timer = threading.Timer(SERVER_LIFETIME, v.stop)
        timer.daemon = True
        timer.start()
        made.append((v, timer))
        return v

    yield make
    for v, timer in made:
        timer.cancel()
        v.stop()


@pytest.fixture
def page(browser):
    p = browser.new_page(viewport={"width": 1280, "height": 800})
    p.dialogs = []
    p.on("dialog", lambda d: (p.dialogs.append(d.message), d.dismiss()))
    yield p
    p.close()


def _until(cond, what: str, limit: float = DEADLINE):
    end = time.monotonic() + limit
    while time.monotonic() < end:
        got = cond()
        if got:
            return got
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}")


def _ws_result(page) -> dict:
    return _until(lambda: page.evaluate("window.__ws && window.__ws.done && window.__ws"), "ws")


# ------------------------------------------------------------------------- script injection
def _payloads(b: int) -> list[str]:
    url = f"http://127.0.0.1:{b}"
    return [
        f"run<iframe style=display:none srcdoc=\"<script>fetch('{url}/iframe');"
        f'parent.__pwned=1</script>"></iframe>',
        f'<img src={url}/img onerror="window.__pwned=2">',
        f'<svg onload="window.__pwned=3"><image href="{url}/svg"/></svg>',
        f"![x]({url}/mdimg) [click](javascript:window.__pwned=4) <{url}/autolink>",
        f"<style>body{{background:url({url}/css)}}</style><script>document.title='pwned'</script>",
    ]


def test_log_strings_are_text_in_the_page(page, beacon, serve, tmp_path):
    p = _payloads(beacon.port)
    logs = [
        write_hostile_log(
            tmp_path / "a.mcap",
            name=p[0],
            paper=p[1],
            kinds=(p[2], "catch"),
            field=f"<img src=http://127.0.0.1:{beacon.port}/field>",
        ),
        write_hostile_log(tmp_path / "b.mcap", name=p[3], paper=p[4], kinds=(p[4],)),
    ]
    viewer = serve(logs)
    page.goto(viewer.url)
    shown = clean(p[0])  # the run's label: the name as one line
    _until(lambda: shown in page.evaluate("document.body.innerText"), "the name shown as text")
    time.sleep(2.0)  # time for anything that would load or run
    text = page.evaluate("document.body.innerText")
    for payload in (p[1], p[2], p[3], f"<img src=http://127.0.0.1:{beacon.port}/field>"):
        assert clean(payload) in text, payload  # shown literally
    assert beacon.hits == []
    assert page.evaluate("window.__pwned") is None
    assert page.title() != "pwned" and page.dialogs == []
    assert page.locator("iframe").count() == 0
    assert (
        page.locator(f"img[src*='{beacon.port}'], svg[onload], a[href^='javascript']").count() == 0
    )

    # control: the same payload unescaped does run (the check above can fail)
    viewer.server.gui.add_markdown(p[0])
    _until(lambda: "/iframe" in beacon.hits, "the unescaped payload to reach the beacon", 30)


# ------------------------------------------------------------------------ foreign origins
def _foreign_pages(tmp_path: Path, beacon: _Beacon, port: int) -> dict[str, str]:
    """name -> URL of a page of another origin whose script opens the viewer's websocket."""
    beacon.page = EVIL_PAGE % (WS_SCRIPT, f"ws://127.0.0.1:{port}")
    local = tmp_path / "evil.html"
    local.write_text(beacon.page)
    return {
        "another port": f"http://127.0.0.1:{beacon.port}/evil.html",
        "another name": f"http://{REBIND}:{beacon.port}/evil.html",
        "file": local.as_uri(),
    }


@pytest.mark.parametrize("which", ["another port", "another name", "file"])
def test_a_page_of_another_origin_gets_nothing(page, beacon, serve, tmp_path, which):
    viewer = serve([write_hostile_log(tmp_path / "s.mcap", name="s")])
    url = _foreign_pages(tmp_path, beacon, viewer.port)[which]
    page.goto(url)
    got = _ws_result(page)
    assert not got["open"] and got["messages"] == 0 and got["bytes"] == 0, got

    # control: the same script in the viewer's own page connects and gets the scene
    page.goto(viewer.url)
    page.evaluate(WS_SCRIPT, f"ws://127.0.0.1:{viewer.port}")
    got = _until(lambda: page.evaluate("window.__ws.messages > 0 && window.__ws"), "own page")
    assert got["open"] and got["bytes"] > 1000


@pytest.mark.parametrize("which", ["another port", "another name", "file"])
def test_without_the_check_the_foreign_page_would_get_the_scene(
    page, beacon, serve, tmp_path, monkeypatch, which
):
    """The control that the refusal above is the check's doing (not the browser's)."""
    monkeypatch.setattr(guard, "refusal", lambda *a: "")
    viewer = serve([write_hostile_log(tmp_path / "s.mcap", name="s")])
    page.goto(_foreign_pages(tmp_path, beacon, viewer.port)[which])
    got = _until(
        lambda: page.evaluate("window.__ws && window.__ws.messages > 0 && window.__ws"), "ws"
    )
    assert got["open"] and got["bytes"] > 1000


def test_dns_rebinding_gets_neither_page_nor_websocket(page, serve, tmp_path):
    viewer = serve([write_hostile_log(tmp_path / "s.mcap", name="s")])
    # the attacker's name now resolves to 127.0.0.1: the page is refused...
    response = page.goto(f"http://{REBIND}:{viewer.port}/")
    assert response is not None and response.status == 403
    # ...and a websocket from that origin, to that name, too
    page.evaluate(WS_SCRIPT, f"ws://{REBIND}:{viewer.port}")
    got = _ws_result(page)
    assert not got["open"] and got["messages"] == 0, got
