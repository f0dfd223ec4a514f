"""The report reads well (issue #37): a headline across papers at the top (per paper the
measured rows reproduced of all, ties, rows whose falsifier was not shown, rows of other regimes
and extensions, configuration and paper rows, and when `replay falsify --store` last ran: the
report reads that record, it does not run the falsifiers, issue #38), and falsifier tables whose
explanation gets the room (it was squeezed into ~100 px beside unbreakable override strings)."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from analysis.claims import counted
from replay.cli import main
from analysis.report.builder import HEADLINE, _headline, build_report

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    logs = tmp_path_factory.mktemp("logs")
    for name in ("stick_2step", "catch_optimised"):
        r = CliRunner().invoke(main, ["run", name, "-q", "-o", str(logs / f"{name}.mcap")])
        assert r.exit_code == 0, r.output
    shutil.copy(ROOT / "data" / "golden" / "grasp_hexahedron.mcap", logs)
    out = tmp_path_factory.mktemp("out") / "report"
    build_report(out, logs)
    return out


def _headline_rows(html: str) -> list[list[str]]:
    table = re.search(r'<table class="headline">(.*?)</table>', html, re.S)
    assert table, "no headline table"
    rows = re.findall(r"<tr>(.*?)</tr>", table.group(1), re.S)
    return [re.findall(r"<t[hd]>(.*?)</t[hd]>", r, re.S) for r in rows]


def test_the_headline_comes_first_and_counts_each_paper(report):
    html = (report / "index.html").read_text()
    assert html.index('id="summary"') < html.index("<section")
    assert '<a href="#summary">' in html
    rows = _headline_rows(html)
    assert rows[0] == list(HEADLINE)
    papers = {r[0]: r for r in rows[1:]}
    stick = papers["Friction Independent Dynamic Capturing Strategy for a 2D Stick-shaped Object"]
    k, n = map(int, stick[1].split(" / "))
    assert 0 < k <= n
    for r in rows[1:]:
        assert re.fullmatch(r"\d+ / \d+", r[1]) and all(x.isdigit() for x in r[2:7])
        # when the stored falsifiers ran (data/claims/falsified.json), or that they never did
        assert re.match(r"\d{4}-\d\d-\d\d \d\d:\d\d UTC, code ", r[7]) or r[7].startswith(
            ("never stored", "none declared")
        ), r[7]
    md = (report / "index.md").read_text()
    assert md.index("## Summary") < md.index("## Friction Independent")
    assert "| " + " | ".join(HEADLINE) + " |" in md


def test_headline_counts_as_the_claims_summary():
    from analysis.claims import Claim, Falsifier, Shown, summary
    from analysis.report.builder import PaperSection

    sec = PaperSection("p", "P", "A")
    sec.claims = [
        Claim("a", "1", "1", "reproduced"),
        Claim("b", "1", "1", "reproduced"),  # its falsifier did not flip it: not counted
        Claim("c", "1", "2", "tie"),
        Claim("x", "1", "1", "reproduced", kind="other regime"),  # never counted
        Claim("d", "1", "1", "consistent", kind="configuration"),
        Claim("e", "1", "1", "consistent", kind="paper"),
    ]
    sec.falsifiers = (Falsifier("a", "v", "run"), Falsifier("b", "w", "run"))
    rows = ({"row": "a", "flipped": True}, {"row": "b", "flipped": False})
    sec.shown = Shown("2026-01-02 03:04 UTC", "0.1.0+abc", "replay falsify p --store", rows)
    ((paper, measured, ties, bare, other, conf, prow, ran),) = _headline(
        [sec, PaperSection("q", "Q", "B")]
    )
    assert counted(sec.claims, sec.shown) == (1, 3)
    assert (paper, measured, ties, bare, other, conf, prow) == (
        "P",
        "1 / 3",
        "1",
        "1",
        "1",
        "1",
        "1",
    )
    assert ran == "2026-01-02 03:04 UTC, code 0.1.0+abc (replay falsify p --store)"
    assert summary(sec.claims, sec.shown).startswith("1 of 3 measured rows")
    sec.shown = None  # never stored: nothing counts
    assert counted(sec.claims, None) == (0, 3)
    assert _headline([sec])[0][7].startswith("never stored: replay falsify p")


def test_falsifier_tables_give_the_explanation_room(report):
    html = (report / "index.html").read_text()
    style = re.search(r"<style>(.*?)</style>", html, re.S).group(1)
    assert re.search(r"table\.falsifiers\s*\{[^}]*table-layout:\s*fixed;[^}]*width:\s*100%", style)
    why = re.search(r"table\.falsifiers col\.why\s*\{\s*width:\s*(\d+)%", style)
    assert why and int(why.group(1)) >= 40
    assert re.search(r"table\.falsifiers td\s*\{[^}]*overflow-wrap:\s*anywhere", style)
    tables = re.findall(r'<table class="falsifiers">(.*?)</table>', html, re.S)
    assert tables
    for t in tables:
        assert t.count("<col ") == 3
        for row in re.findall(r"<tr>(.*?)</tr>", t, re.S)[1:]:
            assert row.count("<td>") == 3
    assert html.count("This report lists them and reads the record: ") == len(tables)


def test_falsifier_explanation_is_wide_in_chromium(report):
    from playwright.sync_api import sync_playwright

    from chromium import FLAGS, _ensure_chromium

    exe = _ensure_chromium()
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=FLAGS)
        try:
            page = browser.new_page(viewport={"width": 1200, "height": 900})
            page.goto((report / "index.html").resolve().as_uri())
            widths = page.evaluate(
                """() => [...document.querySelectorAll('table.falsifiers')].map(t => {
                    const r = t.querySelectorAll('tr')[1].children;
                    return [t.getBoundingClientRect().width, r[2].getBoundingClientRect().width];
                })"""
            )
        finally:
            browser.close()
    assert widths
    for table, why in widths:
        assert why >= 0.4 * table and why >= 300, (table, why)


def test_grasp_fig9_quotes_the_papers_caption(report):
    md = (report / "index.md").read_text()
    assert "Fig. 9 (paper: “Feedback Response”). Regenerated from the run 'grasp_hexahedron'" in md
