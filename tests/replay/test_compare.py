"""``replay compare``: the scenario fields that differ, outcomes and metrics side by side, the
overlaid figures and the Markdown, from short stick runs (friction and seed varied) and a catch
pair (stereo latency varied); a forged log's hostile names stay escaped; unreadable logs are
named. Also ``replay info --events`` / ``--no-events``."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from analysis.commands import COMPARE_HEADER
from replay.log import LogReader, LogWriter
from replay.messages import TOPIC_SCENARIO

from cli_checks import invoke

CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")
HOSTILE = "a\x1b]0;PWNED\x07\x1b[2Jb\rfigure: /etc/forged\nc | x <b>bold</b> [l](javascript:x)"


def row(out: str, name: str) -> list[str]:
    """The cells of the plain-text row ``name`` (split on runs of 2+ spaces)."""
    for line in out.splitlines():
        cells = re.split(r"\s{2,}", line.strip())
        if cells[0] == name:
            return cells[1:]
    raise AssertionError(f"no row {name!r} in:\n{out}")


@pytest.fixture(scope="module")
def logs(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("cmp")
    runs = {
        "base": ("stick_3step",),
        "mu1": ("stick_3step", "--set", "plant.params.stick.friction=1.0", "--seed", "3"),
        "mu0": ("stick_3step", "--set", "plant.params.stick.friction=0.0"),
        "catch": ("catch_optimised",),
        "lat10": ("catch_optimised", "--set", "sensors.stereo.latency=0.01"),
    }
    out = {}
    for key, args in runs.items():
        path = d / f"{key}.mcap"
        r = invoke("run", *args, "--set", "timing.duration=0.5", "-q", "-o", path)
        assert r.exit_code == 0, r.output
        out[key] = path
    return out


def test_stick_runs_side_by_side(logs):
    r = invoke("compare", logs["base"], logs["mu1"], logs["mu0"], "--no-figures")
    assert r.exit_code == 0, r.output
    assert row(r.stdout, "plant.params.stick.friction") == ["0.3", "1", "0"]
    assert row(r.stdout, "seed") == ["0", "3", "0"]
    assert "timing.duration" not in r.stdout  # (alike in all three: not a difference)
    assert row(r.stdout, "#1")[0].startswith("stick_3step (duration 500 ms)")
    assert "friction 1, seed 3" in row(r.stdout, "#2")[0]
    assert len(row(r.stdout, "success")) == 3 and len(row(r.stdout, "collisions")) == 3
    outcomes = [LogReader(logs[k]).outcome()["data"] for k in ("base", "mu1", "mu0")]
    assert [c.rstrip("…") for c in row(r.stdout, "reason")] == [
        o["reason"][: len(c.rstrip("…"))] for o, c in zip(outcomes, row(r.stdout, "reason"))
    ]
    assert row(r.stdout, "success") == ["yes" if o["success"] else "no" for o in outcomes]
    assert "figure:" not in r.stdout


def test_catch_pair_figures_and_markdown(logs, tmp_path):
    md = tmp_path / "cmp.md"
    figs = tmp_path / "figs"
    r = invoke("compare", logs["catch"], logs["lat10"], "-o", figs, "--markdown", md)
    assert r.exit_code == 0, r.output
    assert row(r.stdout, "sensors.stereo.latency") == ["0.001", "0.01"]
    made = [
        Path(line[len("figure: ") :])
        for line in r.stdout.splitlines()
        if line.startswith("figure: ")
    ]
    assert {p.name for p in made} >= {"catch_fig7.png", "catch_fig9.png"}
    assert all(p.is_file() for p in made)
    text = md.read_text()
    assert text.startswith(COMPARE_HEADER + "\n")
    assert "| sensors.stereo.latency | 0.001 | 0.01 |" in text
    for link in re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text):
        assert (md.parent / link).is_file(), link
    again = invoke("compare", logs["catch"], logs["lat10"], "--no-figures", "--markdown", md)
    assert again.exit_code == 0, again.output  # (an earlier comparison: rewritten)
    assert "## Figures" not in md.read_text()


@pytest.mark.parametrize("target", ["notes.md", "log.mcap"])
def test_markdown_never_over_another_file(logs, tmp_path, target):
    path = tmp_path / target
    path.write_text("mine\n")
    r = invoke("compare", logs["base"], logs["mu1"], "--no-figures", "--markdown", path)
    assert r.exit_code == 2 and r.stderr.startswith("error: ") and len(r.stderr.splitlines()) == 1
    assert path.read_text() == "mine\n"


def test_unreadable_logs_are_named_and_fatal_below_two(logs, tmp_path):
    junk = tmp_path / "junk.mcap"
    junk.write_bytes(b"not a log")
    r = invoke("compare", logs["base"], junk, tmp_path / "gone.mcap", logs["mu0"], "--no-figures")
    assert r.exit_code == 0, r.output
    said = r.stderr.splitlines()
    assert any("junk.mcap" in s and s.startswith("warning: left out") for s in said), said
    assert any("gone.mcap" in s for s in said), said
    r = invoke("compare", logs["base"], junk, "--no-figures")
    assert r.exit_code == 2 and "needs 2 readable" in r.stderr, r.output
    assert "Traceback" not in r.output
    r = invoke("compare", logs["base"], logs["base"], "--no-figures")
    assert r.exit_code == 2 and "given twice" in r.stderr


def forge(base: Path, out: Path, **fields) -> Path:
    """A copy of ``base`` whose /scenario message has ``fields`` (test_hostile_outputs')."""
    with LogWriter(out) as w:
        for m in LogReader(base).messages():
            data = dict(m.data, **fields) if m.topic == TOPIC_SCENARIO else m.data
            w.write(m.topic, data, m.t_ns)
    return out


def test_hostile_names_stay_escaped(logs, tmp_path):
    bad = forge(logs["mu0"], tmp_path / "bad.mcap", name=HOSTILE)
    md = tmp_path / "cmp.md"
    r = invoke("compare", logs["base"], bad, "-o", tmp_path / "figs", "--markdown", md)
    assert r.exit_code == 0, r.output
    assert not CONTROL.search(r.stdout) and not CONTROL.search(r.stderr)
    assert not any(line.startswith("figure: /etc") for line in r.stdout.splitlines())
    assert all(p.parent == tmp_path / "figs" for p in (tmp_path / "figs").rglob("*"))
    text = md.read_text()
    assert "<b>" not in text and "](javascript" not in text and not CONTROL.search(text)
    table = [line for line in text.splitlines() if line.startswith("|")]
    cells = {len(re.findall(r"(?<!\\)\|", line)) for line in table}
    assert cells == {4}, table  # (field, #1, #2: a "|" from a log never makes a column)


def test_info_filters_events(logs):
    full = invoke("info", logs["base"])
    listed = [line for line in full.stdout.splitlines() if line.startswith("  t = ")]
    kinds = {line.split()[4] for line in listed}
    assert {"collision", "outcome"} <= kinds
    r = invoke("info", logs["base"], "--events", "outcome,collision")
    shown = [line for line in r.stdout.splitlines() if line.startswith("  t = ")]
    assert shown and {line.split()[4] for line in shown} == {"collision", "outcome"}
    assert len(shown) < len(listed)
    assert f"events: {len(listed)} ({len(shown)} shown: collision, outcome)" in r.stdout
    r = invoke("info", logs["base"], "--no-events")
    assert r.exit_code == 0 and f"events: {len(listed)}" in r.stdout
    assert not any(line.startswith("  t = ") for line in r.stdout.splitlines())
    assert "/stick/state" in r.stdout  # (the rest as before)
    r = invoke("info", logs["base"], "--events", "nope")
    assert r.exit_code == 0 and "no event of kind nope" in r.stderr and "collision" in r.stderr
    r = invoke("info", logs["base"], "--events", "outcome", "--no-events")
    assert r.exit_code == 2 and r.stderr.startswith("error: ")


def test_figures_that_fail_leave_no_empty_folder(logs, tmp_path):
    m = next(LogReader(logs["lat10"]).messages(TOPIC_SCENARIO))
    assert "latency: 0.01" in m.data["yaml"]
    bad = forge(
        logs["lat10"],
        tmp_path / "bad.mcap",
        yaml=m.data["yaml"].replace("latency: 0.01", "latency: -5"),
    )
    r = invoke("compare", logs["catch"], bad, "-o", tmp_path / "figs" / "new")
    assert r.exit_code == 1 and "could not be made" in r.stderr, r.output
    assert not (tmp_path / "figs").exists()  # neither folder it made is left behind
    kept = tmp_path / "mine"
    kept.mkdir()
    r = invoke("compare", logs["catch"], bad, "-o", kept)
    assert r.exit_code == 1 and kept.is_dir()  # a folder the user made stays
