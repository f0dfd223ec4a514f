"""The viewer against hostile logs and hostile clients, without a browser (issue #36).

- Text from a log reaches Viser's markdown escaped: rendered by a CommonMark parser with raw
  HTML on (as Viser's client does), it is the same text back, with no tag, link or entity.
- A stored scenario YAML that is a number, nested 20,000 deep, too big, not text, or has
  ``plant`` / ``plant.params`` / ``sensors`` of the wrong shape is one warning line; the
  viewer serves.
- The websocket refuses a foreign ``Origin`` or ``Host`` (403, one line), lets in the viewer's
  own page and clients without ``Origin``; bad frames and bad GUI values are one line each, no
  traceback, and the server serves on.
"""

from __future__ import annotations

import asyncio
import html
import re
import socket
import time
from typing import cast

import msgspec
import pytest
import viser
import websockets
from click.testing import CliRunner
from markdown_it import MarkdownIt

from replay.cli import main
from replay.viewer import ViewerError, load_run
from replay.viewer import app as viewer_app
from replay.viewer import guard
from replay.viewer.app import Viewer
from replay.viewer.markup import clean, plain
from synthetic_logs import write_hostile_log
from replay.viewer.timeline import DEFAULT_SPEED

SUBPROTOCOL = f"viser-v{viser.__version__}"
PAYLOADS = [
    'run<iframe style=display:none srcdoc="<script>alert(parent.location.href)</script>"></iframe>',
    "<img src=x onerror=alert(1)>",
    "<svg onload=alert(1)>",
    "<script>alert(1)</script>",
    "[x](javascript:alert(1))",
    "![x](http://127.0.0.1:9/x.png)",
    "<http://127.0.0.1:9/autolink> <javascript:alert(1)>",
    "https://evil.example www.evil.example a@evil.example",
    "&lt;script&gt; &#60;b&#62; **bold** _em_ `code` \\ back",
    "# heading\n- list\n\n    indented\n| a | b |",
    "a\x1b]0;title\x07b\x1b[2J\rc\u2028d",
    "catch_a snake_case_x __dunder__ a__b _em_ x_ _y ***z***",
]


@pytest.fixture
def viewers():
    made: list[Viewer] = []
    yield made
    for v in made:
        v.stop()


def _wait_for(cond, what, limit=20.0):
    end = time.monotonic() + limit
    while time.monotonic() < end:
        if cond():
            return
        time.sleep(0.02)
    raise AssertionError(f"never happened: {what}")


# ------------------------------------------------------------------------ text from a log
@pytest.mark.parametrize("payload", PAYLOADS)
def test_plain_renders_as_the_same_text(payload):
    md = MarkdownIt("commonmark", {"html": True})
    out = md.render(f"**{plain(payload)}**").strip()
    assert out.startswith("<p><strong>") and out.endswith("</strong></p>"), out
    inner = out[len("<p><strong>") : -len("</strong></p>")]
    assert "<" not in inner and ">" not in inner  # no tag: markdown-it escapes text's < >
    assert html.unescape(inner) == clean(payload, 10_000)


def test_clean_is_one_bounded_line():
    assert clean("a\nb\x1b[2J\x9bc\u2028") == "a b [2J c "
    assert len(clean("x" * 10_000)) == 120 and clean("x" * 10_000).endswith("…")


def _markdown_sent(monkeypatch) -> list[str]:
    """Every markdown content the viewer gives Viser (added or set later)."""
    sent: list[str] = []
    add = viser.GuiApi.add_markdown

    def recording_add(self, content, **kw):
        sent.append(content)
        return add(self, content, **kw)

    monkeypatch.setattr(viser.GuiApi, "add_markdown", recording_add)
    prop = cast(property, viser.GuiMarkdownHandle.content)

    def recording_set(self, value):
        sent.append(value)
        prop.fset(self, value)

    monkeypatch.setattr(viser.GuiMarkdownHandle, "content", property(prop.fget, recording_set))
    return sent


_OWN_MARKUP = re.compile(r"<span style='color:rgb\(\d+, \d+, \d+\)'>■</span>")


def test_log_strings_reach_markdown_escaped(tmp_path, monkeypatch, viewers):
    sent = _markdown_sent(monkeypatch)
    logs = [
        write_hostile_log(
            tmp_path / f"h{k}.mcap",
            name=f"{k}{p}",
            paper=p,
            kinds=(p, "catch"),
            field=f"f{p}",
        )
        for k, p in enumerate(PAYLOADS[:4])
    ]
    v = Viewer.open(logs, port=0)
    viewers.append(v)
    v.show(0.1)
    assert len(sent) > 5 and any("events:" in s for s in sent)
    md = MarkdownIt("commonmark", {"html": True})
    for content in sent:
        rendered = md.render(_OWN_MARKUP.sub("", content))
        tags = set(re.findall(r"</?([a-zA-Z0-9]+)", rendered))
        assert tags <= {"p", "strong", "em", "ul", "li", "br"}, (tags, content)
        assert "&amp;lt;" not in rendered or "&lt;" in html.unescape(rendered)
    text = "\n".join(sent)
    for p in PAYLOADS[:4]:
        assert p not in text
    # the notes name the hostile field, escaped; the labels are the cleaned names
    assert any("changes shape" in s for s in sent)
    assert [r.label for r in v.runs] == [clean(f"{k}{p}") for k, p in enumerate(PAYLOADS[:4])]


def test_labels_and_event_kinds_are_bounded_lines(tmp_path):
    path = write_hostile_log(
        tmp_path / "long.mcap", name="n\x1b[2J" + "x" * 5000, kinds=("k\n" + "y" * 5000,)
    )
    run = load_run(path)
    assert len(run.label) <= 120 and "\x1b" not in run.label
    kinds = [e["kind"] for e in run.events]
    assert all(len(k) <= 120 and "\n" not in k for k in kinds)


# ------------------------------------------------------------------------- stored YAML
def _view(path):
    r = CliRunner().invoke(
        main, ["view", str(path), "--port", "0", "--timeout", "0.1"], catch_exceptions=False
    )
    lines = [line for line in r.output.splitlines() if line.strip()]
    assert r.exit_code == 0, r.output
    assert "Traceback" not in r.output
    assert all(line.startswith(("warning: ", "note: ", "viewer: ")) for line in lines), r.output
    assert lines[-1].startswith("viewer: http://127.0.0.1:")
    return lines


@pytest.mark.parametrize(
    "yaml_text,said",
    [
        ("12345", "not a mapping"),
        ("[" * 20000 + "]" * 20000, "nested too deep"),
        ("{a: " * 20000 + "1" + "}" * 20000, "nested too deep"),
        ("name: x\nplant: {type: airtable, params: [1, 2]}\n", "plant.params is not a mapping"),
        ("name: x\nplant: [airtable]\n", "plant is not a mapping"),
        ("name: x\nplant: {type: airtable}\nsensors: [1, 2]\n", None),
        ("name: x\nsensors: {cam: [1], c2: {type: stereo_ball, params: [1]}}\n", None),
        ("a: [unclosed\n", "YAML unreadable (ParserError)"),
        ("# " + "x" * 1_000_000 + "\nname: x\n", "REPLAY_LIMIT_SCENARIO_BYTES=N"),
    ],
    ids=["number", "deep-list", "deep-map", "params-list", "plant-list", "sensors-list",
         "sensor-params-list", "bad-yaml", "too-big"],
)  # fmt: skip
def test_view_a_bad_stored_yaml_is_one_line(tmp_path, yaml_text, said):
    path = write_hostile_log(tmp_path / "y.mcap", name="y", yaml_text=yaml_text)
    lines = _view(path)
    if said is not None:
        hits = [line for line in lines if said in line]
        assert len(hits) == 1 and hits[0].startswith("warning: "), lines


def test_view_odd_events_and_a_non_text_yaml(tmp_path):
    from replay.log import LogWriter
    from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO, TOPIC_STICK_STATE

    path = tmp_path / "odd.mcap"
    with LogWriter(path) as log:
        log.write(TOPIC_SCENARIO, {"name": ["a", 1], "paper": {"x": 1}, "yaml": 123}, 0)
        for k in range(20):
            state = {"t": k * 0.01, "x": 0, "y": 0, "theta": 0, "vx": 0, "vy": 0, "omega": 0}
            log.write(TOPIC_STICK_STATE, state, k)
        log.write(TOPIC_EVENTS, {"t": "soon", "kind": 5, "data": "finger"}, 1000)
        log.write(TOPIC_EVENTS, {"t": None, "kind": None, "data": [1]}, 2000)
        log.write(TOPIC_EVENTS, {"kind": "catch", "data": {"parts": list(range(10**4))}}, 3000)
    lines = _view(path)
    assert any("scenario YAML unreadable (not text)" in line for line in lines)
    run = load_run(path)
    assert [e["t"] for e in run.events] == pytest.approx([1e-6, 2e-6, 3e-6])
    assert [e["kind"] for e in run.events] == ["5", "None", "catch"]


# ------------------------------------------------------------------------ who may connect
def _handshake(port: int, host: str | None, origin: str | None, upgrade: bool = True) -> int:
    """The HTTP status the viewer answers a request with these headers (101: a websocket)."""
    lines = ["GET / HTTP/1.1"]
    if host is not None:
        lines.append(f"Host: {host}")
    if upgrade:
        lines += [
            "Upgrade: websocket",
            "Connection: Upgrade",
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
            "Sec-WebSocket-Version: 13",
            f"Sec-WebSocket-Protocol: {SUBPROTOCOL}",
        ]
    if origin is not None:
        lines.append(f"Origin: {origin}")
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
        head = s.recv(64).decode("latin-1")
    return int(head.split()[1])


@pytest.fixture
def served(tmp_path, viewers):
    v = Viewer.open([write_hostile_log(tmp_path / "s.mcap", name="s")], port=0)
    viewers.append(v)
    return v


def test_foreign_origin_and_host_are_refused(served, capfd):
    port = served.port
    me = f"127.0.0.1:{port}"
    refused = [
        (me, "http://evil.example"),
        (me, "null"),  # a file:// page, a sandboxed frame
        (me, f"http://127.0.0.1:{port + 1}"),
        (me, f"http://localhost.evil.example:{port}"),
        (me, f"https://127.0.0.1:{port}"),
        (me, f"http://127.0.0.1:{port}@evil.example"),
        (f"evil.example:{port}", None),  # DNS rebinding: the attacker's name, our address
        (f"evil.example:{port}", f"http://evil.example:{port}"),
        (f"127.0.0.1:{port + 1}", None),
        ("127.0.0.1", None),  # port 80 implied
        (f"127.0.0.1:{port}:1", None),
    ]
    for host, origin in refused:
        assert _handshake(port, host, origin) == 403, (host, origin)
    assert _handshake(port, f"evil.example:{port}", None, upgrade=False) == 403
    allowed = [
        (me, None),  # not a browser page
        (None, None),
        (me, f"http://{me}"),
        (f"localhost:{port}", f"http://localhost:{port}"),
        (f"LOCALHOST:{port}", f"http://[::1]:{port}"),
    ]
    for host, origin in allowed:
        assert _handshake(port, host, origin) == 101, (host, origin)
    assert _handshake(port, me, None, upgrade=False) == 200  # the page itself
    err = capfd.readouterr().err
    lines = err.splitlines()
    assert "Traceback" not in err
    refusals = [line for line in lines if "refused a connection" in line]
    assert len(refusals) == len(refused) + 1, err
    assert all(line.startswith("warning: viewer: ") for line in lines), err


def test_a_refused_client_receives_nothing(served):
    async def go():
        async with websockets.connect(
            f"ws://127.0.0.1:{served.port}",
            subprotocols=[SUBPROTOCOL],
            additional_headers={"Origin": "http://evil.example"},
        ) as ws:
            return await ws.recv()

    with pytest.raises(websockets.exceptions.InvalidStatus) as exc:
        asyncio.run(go())
    assert exc.value.response.status_code == 403 and b"Forbidden" in exc.value.response.body


@pytest.mark.parametrize(
    "served_on,local,ok,bad",
    [
        ("127.0.0.1", "127.0.0.1", {"localhost", "127.0.0.1", "::1"}, {"evil.example"}),
        ("::1", "::1", {"localhost", "::1", "127.0.0.1"}, {"evil.example"}),
        ("0.0.0.0", "192.0.2.7", {"192.0.2.7", "0.0.0.0"}, {"localhost", "evil.example"}),
        ("0.0.0.0", "::ffff:127.0.0.1", {"127.0.0.1", "localhost", "0.0.0.0"}, {"evil.example"}),
        ("::", "::1", {"::1", "::", "localhost"}, {"evil.example", "0.0.0.0"}),
        ("myhost.lan", "192.0.2.7", {"myhost.lan", "192.0.2.7"}, {"localhost", "evil.example"}),
        ("127.0.0.1", "127.0.0.1", set(), {"0.0.0.0", "::", ""}),
    ],
)
def test_allowed_names(served_on, local, ok, bad):
    names = guard.allowed_names(served_on, local)
    assert ok <= names and not (bad & names)


def test_the_server_is_not_served_unguarded(monkeypatch):
    import contextlib

    @contextlib.contextmanager
    def unguarded(host):
        yield []

    monkeypatch.setattr(guard, "guarded_serve", unguarded)
    with pytest.raises(ViewerError, match="cannot check who connects"):
        viewer_app.start_server("127.0.0.1", 0)


# ------------------------------------------------------------------------------ bad frames
# what a browser sends first: Viser takes a client as connected (its GUI updates as heard) once
# its camera is known
CAMERA = msgspec.msgpack.encode(
    {
        "type": "ViewerCameraMessage",
        "wxyz": [1.0, 0.0, 0.0, 0.0],
        "position": [1.0, 1.0, 1.0],
        "fov": 1.0,
        "near": 0.01,
        "far": 100.0,
        "image_height": 600,
        "image_width": 800,
        "look_at": [0.0, 0.0, 0.0],
        "up_direction": [0.0, 0.0, 1.0],
    }
)


def test_bad_frames_are_one_line_each_and_the_server_serves_on(served, capfd):
    v = served
    update = msgspec.msgpack.encode

    def gui(uuid, **updates):
        return update({"type": "GuiUpdateMessage", "uuid": uuid, "updates": updates})

    slider, speed = v.timeline.slider._impl.uuid, v.timeline.speed._impl.uuid
    bad = [
        b"\x00\x01garbage",
        "a text frame",
        update({"type": "NoSuchMessage"}),
        update([1, 2, 3]),
        update({"type": "GuiUpdateMessage"}),
        update({"type": "ViewerCameraMessage", "fov": "wide"}),
        gui(slider, value="abc"),
        gui(slider, value=float("nan")),
        gui(slider, value=1e300),
        gui(slider, no_such_prop=1),
        gui(speed, value="<img src=x onerror=alert(1)>"),
    ]

    async def send_all():
        for frame in bad:
            try:
                async with websockets.connect(
                    f"ws://127.0.0.1:{v.port}", subprotocols=[SUBPROTOCOL], max_size=None
                ) as ws:
                    await ws.send(CAMERA)
                    await ws.send(frame)
                    await asyncio.sleep(0.2)
            except websockets.exceptions.ConnectionClosed:
                pass

    asyncio.run(send_all())
    _wait_for(lambda: v.timeline.speed.value == DEFAULT_SPEED, "the speed put back")
    _wait_for(lambda: 0.0 <= v.time <= v.timeline.t1, "the time put back in the run")
    time.sleep(0.3)
    err = capfd.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err and "Task exception" not in err, err
    assert 4 <= len(lines) <= len(bad), err
    assert all(line.startswith("warning: viewer: ") for line in lines), err
    assert "<img" not in v.timeline.status.content

    # the server serves on: a new client gets the scene
    async def fresh():
        async with websockets.connect(
            f"ws://127.0.0.1:{v.port}", subprotocols=[SUBPROTOCOL], max_size=None
        ) as ws:
            return len(await asyncio.wait_for(ws.recv(), 10))

    assert asyncio.run(fresh()) > 1000
    v.seek(0.1)
    assert abs(v.time - 0.1) < 1e-9


def test_view_a_log_without_the_fields_its_scene_reads_is_one_line(tmp_path):
    from replay.log import LogWriter
    from replay.messages import TOPIC_STICK_STATE

    path = tmp_path / "fields.mcap"
    with LogWriter(path) as log:
        for k in range(20):
            log.write(TOPIC_STICK_STATE, {"t": k * 0.01, "x": 0.0, "y": 0.0, "theta": 0.0}, k)
    r = CliRunner().invoke(main, ["view", str(path), "--port", "0", "--timeout", "0.1"])
    lines = [line for line in r.output.splitlines() if line.strip()]
    assert r.exit_code == 2 and "Traceback" not in r.output, r.output
    assert lines[-1] == f"error: {path}: cannot draw it (KeyError: 'vx')", r.output


def test_a_bare_connect_or_a_request_that_is_not_http_says_nothing(served, capfd):
    for junk in (b"", b"NOT HTTP AT ALL\r\n\r\n", b"\x16\x03\x01\x02\x00" + b"\x00" * 64):
        with socket.create_connection(("127.0.0.1", served.port), timeout=10) as s:
            s.sendall(junk)
            s.shutdown(socket.SHUT_WR)
            s.settimeout(10)
            while s.recv(4096):
                pass
    assert _handshake(served.port, f"127.0.0.1:{served.port}", None) == 101  # serves on
    time.sleep(0.2)
    assert capfd.readouterr().err == ""
