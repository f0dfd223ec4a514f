"""The theses' verdicts come from the ablation tables, and README.md shows what the stored tables
say (``replay theses --stored --markdown``)."""

from __future__ import annotations

import pytest

from analysis import theses
from conftest import ROOT
from replay.sweep import ablations
from replay.sweep.table import read_table

START, END = "<!-- theses:start -->", "<!-- theses:end -->"
VERDICTS = ("holds", "holds only when", "does not hold")


def test_readme_shows_the_stored_tables_verdicts():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    shown = text.split(START, 1)[1].split(END, 1)[0].strip()
    want = theses.markdown(theses.verdicts(stored_only=True))
    assert shown == want, "README.md's theses differ: paste `replay theses --stored --markdown`"


@pytest.mark.parametrize("thesis", theses.THESES, ids=lambda t: t.tables[0])
def test_every_thesis_has_a_verdict_from_its_stored_tables(thesis):
    v = theses.decide(thesis, stored_only=True)
    assert v.source == "stored"
    assert v.verdict.startswith(VERDICTS), v.verdict
    assert "/" in v.numbers or "%" in v.numbers  # counts or rates with their intervals
    assert v.figure


@pytest.mark.parametrize("thesis", theses.THESES, ids=lambda t: t.tables[0])
def test_a_verdict_follows_its_table(thesis, monkeypatch):
    """Half of every table's runs left out: the numbers change with them (none is written by
    hand)."""
    before = theses.decide(thesis, stored_only=True)
    halved = {name: read_table(ablations.STORED_DIR / f"{name}.csv")[::2] for name in thesis.tables}
    monkeypatch.setattr(theses, "_tables", lambda names, stored_only: (halved, "stored"))
    after = theses.decide(thesis, stored_only=True)
    assert after.numbers != before.numbers


def test_a_thesis_without_its_table_says_how_to_run_it(monkeypatch, tmp_path):
    monkeypatch.setattr(ablations, "STORED_DIR", tmp_path)
    v = theses.decide(theses.THESES[0], stored_only=True)
    assert v.verdict == theses.NOT_RUN and "replay ablate" in v.numbers


def test_the_markdown_escapes_what_a_table_says():
    v = theses.Verdict(theses.THESES[0], "holds | <b>", "1/2 [x](y)", "fig", "stored")
    line = theses.markdown([v]).splitlines()[-1]
    assert "<b>" not in line and "\\|" in line and "](" not in line


def test_a_damaged_fresh_table_is_said_not_a_traceback(tmp_path, monkeypatch):
    from cli_checks import invoke

    monkeypatch.chdir(tmp_path)
    fresh = tmp_path / "out" / "ablations" / "catch_rate"
    fresh.mkdir(parents=True)
    (fresh / "table.csv").write_text("index,key,success\n0,abc,True\n", encoding="utf-8")
    r = invoke("theses")
    assert r.exit_code == 0 and "Traceback" not in r.output, r.output
    assert f"{theses.UNREAD}: its table (run here) could not be read: KeyError" in r.output
