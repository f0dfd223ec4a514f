"""What a reader keeps of a log is bounded (issue #36): one topic's messages at most
``series_bytes`` as stored, counted before each is decoded; the /scenario message's fields
typed and clipped, so that a long stored name costs the commands that print it nothing."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from replay.cli import main
from replay.log import LogReader, LogWriter
from replay.log import reader as reader_module
from replay.log.errors import LogLimitError
from replay.log.reader import DESCRIPTION_CHARS, TEXT_CHARS
from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO, Event, ScenarioInfo

EVENT_BYTES = len(json.dumps({"t": 0.0, "kind": "plan", "data": {"s": "a" * 1000}}))


def _events_log(path: Path, n: int, *, scenario: dict | None = None) -> Path:
    """A log of a /scenario message and ``n`` /events of ~1 KB each."""
    info = {"t": 0.0, "name": "e", "paper": "p", "yaml": "a: 1\n", "seed": 0, "version": "v"}
    with LogWriter(path, chunk_size=4096) as log:
        log.write(TOPIC_SCENARIO, {**info, **(scenario or {})}, 0)
        for i in range(n):
            log.write(TOPIC_EVENTS, Event(i * 1e-3, "plan", {"s": "a" * 1000}), i * 10**6)
    return path


def _cut(path: Path) -> Path:
    """``path`` without its summary (a run killed mid-way): read record by record."""
    data = path.read_bytes()
    out = path.with_name("cut.mcap")
    out.write_bytes(data[: len(data) * 9 // 10])
    return out


@pytest.mark.parametrize("torn", [False, True])
def test_a_topic_over_series_bytes_is_one_limit_error_before_it_is_decoded(
    tmp_path, monkeypatch, torn
):
    path = _events_log(tmp_path / "ev.mcap", 40)
    path = _cut(path) if torn else path
    decoded = []
    decode = reader_module._decode
    monkeypatch.setattr(reader_module, "_decode", lambda d: decoded.append(d) or decode(d))
    monkeypatch.setenv("REPLAY_LIMIT_SERIES_BYTES", str(int(EVENT_BYTES * 10.5)))
    r = LogReader(path)
    assert r.truncated == torn
    for ask in (r.events, lambda: r.series(TOPIC_EVENTS), r.outcome):
        decoded.clear()
        with pytest.raises(LogLimitError) as err:
            ask()
        assert len(decoded) == 10  # the 11th is counted, not decoded
        text = str(err.value)
        assert "\n" not in text and "REPLAY_LIMIT_SERIES_BYTES" in text and TOPIC_EVENTS in text
    assert r.scenario()["name"] == "e"  # (another topic: its own count)
    streamed = len(list(r.messages(TOPIC_EVENTS)))  # (keeps nothing: not bounded)
    assert streamed == 40 or torn and 10 < streamed < 40
    monkeypatch.setenv("REPLAY_LIMIT_SERIES_BYTES", str(EVENT_BYTES * 40))
    assert len(LogReader(path).events()) == streamed


def test_a_bad_series_limit_variable_is_one_limit_error(tmp_path, monkeypatch):
    r = LogReader(_events_log(tmp_path / "ev.mcap", 2))
    monkeypatch.setenv("REPLAY_LIMIT_SERIES_BYTES", "lots")
    with pytest.raises(LogLimitError, match="REPLAY_LIMIT_SERIES_BYTES"):
        r.series(TOPIC_EVENTS)


@pytest.fixture(scope="module")
def stick_events(tmp_path_factory) -> Path:
    """A real stick_3step run (~0.3 s) with 40 more ~1 KB events."""
    d = tmp_path_factory.mktemp("stick")
    r = CliRunner().invoke(main, ["run", "stick_3step", "-q", "-o", str(d / "base.mcap")])
    assert r.exit_code == 0, r.output
    with LogWriter(d / "ev.mcap") as w:
        for m in LogReader(d / "base.mcap").messages():
            w.write(m.topic, m.data, m.t_ns)
        for i in range(40):
            w.write(TOPIC_EVENTS, Event(0.5, "plan", {"s": "a" * 1000}), 500_000_000)
    return d / "ev.mcap"


@pytest.mark.parametrize(
    "command",
    [
        "figures",
        "info",
        "claims",
    ],
)
def test_a_command_over_series_bytes_says_one_line(tmp_path, monkeypatch, stick_events, command):
    monkeypatch.setenv("REPLAY_LIMIT_SERIES_BYTES", str(EVENT_BYTES * 30))
    out = ["-o", str(tmp_path / "f")] if command == "figures" else []
    r = CliRunner().invoke(main, [command, str(stick_events), *out], prog_name="replay")
    assert "Traceback" not in r.output and not isinstance(r.exception, LogLimitError)
    errors = [x for x in r.stderr.splitlines() if x.startswith("error:")]
    assert r.exit_code == 2 and len(errors) == 1, r.output
    assert "REPLAY_LIMIT_SERIES_BYTES" in errors[0]


# -- the /scenario message -------------------------------------------------------------------


def test_a_normal_scenario_reads_as_written(tmp_path):
    with LogWriter(tmp_path / "s.mcap") as log:
        log.write(TOPIC_SCENARIO, ScenarioInfo(0.0, "stick", "p", "a: 1\n", 2**63 - 1, "1.0"), 0)
    sc = LogReader(tmp_path / "s.mcap").scenario()
    assert sc == {
        "name": "stick",
        "paper": "p",
        "yaml": "a: 1\n",
        "seed": 2**63 - 1,
        "version": "1.0",
    }


def test_long_stored_texts_are_clipped_and_stay_distinct(tmp_path):
    long = "A" * 2_000_000
    yaml_text = f"description: {'d' * 500_000}\n"
    scs = [
        LogReader(
            _events_log(
                tmp_path / f"{i}.mcap",
                1,
                scenario={"name": long + i, "paper": long, "version": long, "yaml": yaml_text},
            )
        ).scenario()
        for i in "12"
    ]
    for sc in scs:
        for key in ("name", "paper", "version"):
            assert len(sc[key]) <= TEXT_CHARS and sc[key].startswith("A" * 100) and "…" in sc[key]
        assert len(sc["description"]) <= DESCRIPTION_CHARS and sc["description"].startswith("ddd")
    assert scs[0]["name"] != scs[1]["name"] and scs[0]["paper"] == scs[1]["paper"]
    exact = "x" * TEXT_CHARS
    sc = LogReader(_events_log(tmp_path / "x.mcap", 1, scenario={"name": exact})).scenario()
    assert sc["name"] == exact


@pytest.mark.parametrize(
    "fields",
    [
        {"seed": "S" * 1_000_000},
        {"seed": -1},
        {"seed": 2**63},
        {"seed": 10**400},
        {"seed": True},
        {"seed": 1.5},
        {"name": ["a"] * 100_000},
        {"paper": {"x": 1}},
        {"version": 3},
        {"yaml": "description: [1, 2]\n"},
    ],
)
def test_a_stored_field_of_another_type_is_left_out(tmp_path, fields):
    sc = LogReader(_events_log(tmp_path / "s.mcap", 1, scenario=fields)).scenario()
    (key,) = fields
    key = "description" if key == "yaml" else key
    assert key not in sc and sc.get(key) is None
    types = {"name": str, "paper": str, "version": str, "seed": int, "yaml": str}
    assert {k: type(v) for k, v in sc.items()} == {k: t for k, t in types.items() if k != key}


def test_info_and_figures_of_a_long_name_are_fast_and_bounded(tmp_path):
    huge = "N" * 5_000_000
    path = _events_log(
        tmp_path / "long.mcap", 1, scenario={"name": huge, "paper": "higashimori2007"}
    )
    t0 = time.monotonic()
    r = CliRunner().invoke(main, ["info", str(path)], prog_name="replay")
    assert r.exit_code == 0, r.output
    assert max(len(line) for line in r.output.splitlines()) < 400
    r = CliRunner().invoke(main, ["figures", str(path), "-o", str(tmp_path / "f")])
    assert max(len(line) for line in r.output.splitlines()) < 400
    assert time.monotonic() - t0 < 20  # (before: a 2 MB name's figures took over 100 s)
