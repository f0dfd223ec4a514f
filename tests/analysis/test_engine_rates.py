"""Issue #24: the robustness rates of both engines on the same inputs, stored
(data/ablations/engine_rates.csv, ``python -m analysis.engine_rates``) and shown beside the
per-engine claims rows by ``replay claims`` and the report (analysis.engines.evaluate_runs)."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis.engine_rates import (
    CATCH_SCENARIOS,
    GRASP_PATHS,
    GRASP_SCENARIOS,
    TABLE,
    catch_set,
    grasp_set,
    markdown,
    read,
    run_catch,
    run_grasp,
    write,
)
from analysis.engines import ENGINES, evaluate_runs, stored_rate_rows

ROOT = Path(__file__).resolve().parents[2]
STORED = ROOT / "data" / "ablations" / f"{TABLE}.csv"


@pytest.fixture(scope="module")
def stored():
    rows = read(STORED)
    assert rows, f"no stored table: run python -m analysis.engine_rates ({STORED})"
    return rows


def test_the_stored_table_runs_both_engines_on_the_same_inputs(stored):
    sets = dict.fromkeys(r["set"] for r in stored)
    assert {s.split(":")[0] for s in sets} == set(CATCH_SCENARIOS) | set(GRASP_SCENARIOS)
    for s in sets:
        cases = {
            e: [r["case"] for r in stored if r["set"] == s and r["engine"] == e] for e in ENGINES
        }
        assert cases["PyBullet"] == cases["MuJoCo"] and len(cases["MuJoCo"]) >= 20, s
        assert len(set(cases["MuJoCo"])) == len(cases["MuJoCo"]), s
    for name in GRASP_SCENARIOS:
        assert grasp_set(name, len(GRASP_PATHS)) in sets
    for r in stored_rate_rows("namiki2003", STORED) + stored_rate_rows("namiki1999", STORED):
        if "engines part" in r.note:  # a probe says what decides it
            assert "; probe MuJoCo, " in r.note, r


def test_no_stored_run_flags_success_that_its_criterion_rejects(stored):
    for r in stored:
        assert r["reason"], r
        assert r["success"] or not r["flag"], r  # the grasp's flag never beats the physics
        if r["paper"] == "namiki2003":
            assert r["success"] == (r["reason"] == "caught"), r


def test_both_engines_reach_the_bar_on_every_stored_set(stored):
    """Issue #24's done-when: >= 90 % in MuJoCo on the perturbed throws and the unseen human
    paths; the PyBullet twins' rates on the same inputs beside them."""
    rows = stored_rate_rows("namiki2003", STORED) + stored_rate_rows("namiki1999", STORED)
    print("\n" + markdown(stored))
    assert len(rows) == len(CATCH_SCENARIOS) + len(GRASP_SCENARIOS)
    for r in rows:
        assert r.measured.startswith("PyBullet: ") and " ‖ MuJoCo: " in r.measured, r
        assert "%]" in r.measured and "engine_rates.csv" in r.note, r  # interval, source
        # a test the papers did not make, against a project target: shown, never counted; the
        # target is in the note, "paper states" holds what the paper states (issue #38)
        assert r.kind == "extension" and "issue #24" in r.note, r
        assert "90 %" not in r.stated and "issue" not in r.stated, r
    mujoco = [r for r in rows if r.quantity.startswith(("catch_optimised", "grasp_"))]
    assert all(r.status == "reproduced" for r in mujoco), mujoco


def test_the_stored_runs_are_this_codes(tmp_path, stored):
    """The first throw and the first human path again, in both engines: the same verdicts."""
    fresh = run_catch(2, names=CATCH_SCENARIOS[:1]) + run_grasp(
        GRASP_PATHS[:1], names=GRASP_SCENARIOS[:1]
    )
    n = sum(r["set"].startswith(CATCH_SCENARIOS[0]) and r["engine"] == "MuJoCo" for r in stored)
    for r in fresh:
        s = (
            grasp_set(r["scenario"], len(GRASP_PATHS))
            if r["paper"] == "namiki1999"
            else catch_set(r["scenario"], n)
        )
        old = next(
            o
            for o in stored
            if o["set"] == s and o["engine"] == r["engine"] and o["case"] == r["case"]
        )
        assert (old["success"], old["reason"], old["flag"]) == (
            r["success"],
            r["reason"],
            r["flag"],
        ), (old, r)
    write(fresh, tmp_path / "t.csv")  # the table reads back as written
    assert read(tmp_path / "t.csv") == fresh


def test_rows_where_the_engines_part_say_why(tmp_path):
    rows = []
    for i in range(10):
        for engine, ok in (("PyBullet", True), ("MuJoCo", i < 6)):
            rows.append(
                {
                    "paper": "namiki2003",
                    "set": "s",
                    "scenario": "catch_optimised",
                    "engine": engine,
                    "case": f"throw {i}",
                    "success": ok,
                    "reason": "caught" if ok else "ball bounced off finger f1",
                    "flag": ok,
                }
            )
    probe = "MuJoCo, mj_solref [0.002, 1.5]"
    rows += [dict(r, engine=probe, success=True, reason="caught") for r in rows[1::2]]
    write(rows, tmp_path / "t.csv")
    (r,) = stored_rate_rows("namiki2003", tmp_path / "t.csv")
    assert f"probe {probe}: 10/10 = 100 % [72–100 %]" in r.note
    assert r.status == "differs"
    assert r.note.startswith("engines part: PyBullet reproduced, MuJoCo differs")
    assert "MuJoCo failures: 4× ball bounced off finger f1" in r.note
    assert "MuJoCo: 6/10 = 60 % [31–83 %]" in r.measured
    assert stored_rate_rows("namiki1999", tmp_path / "t.csv") == []


def test_claims_show_the_rates_only_beside_both_engines(stored):
    class Log:
        def __init__(self, paper):
            self.paper = paper

        def scenario(self):
            return {"paper": self.paper}

    from analysis.claims import Claim

    def evaluate(logs):
        return [Claim(f"{n}: q", "1", "1", "reproduced") for n in logs]

    rows, note = evaluate_runs(evaluate, {"grasp_sphere": Log("namiki1999")})
    assert len(rows) == 1 and note == ""  # one engine: the paper's rows alone
    logs = {n: Log("namiki1999") for n in ("grasp_sphere", "grasp_sphere_mujoco")}
    rows, note = evaluate_runs(evaluate, logs)
    rates = [r for r in rows if "engine_rates.csv" in r.note]
    assert [r.quantity for r in rates] == [grasp_set(n, len(GRASP_PATHS)) for n in GRASP_SCENARIOS]
    both = note.splitlines()[0]  # the closing note: the paper's rows and the rates
    assert "grasp_sphere: q" in both and all(r.quantity in both for r in rates), note


def test_the_report_names_the_mujoco_version():
    from importlib import metadata

    from analysis.report.builder import _provenance

    assert _provenance("x")["mujoco"] == metadata.version("mujoco")


def test_the_report_names_the_command_of_the_stored_rates():
    from types import SimpleNamespace

    from analysis.engine_rates import COMMAND
    from analysis.report.builder import _commands

    rows = stored_rate_rows("namiki2003", STORED)
    with_rates = [SimpleNamespace(runs=[], falsifiers=(), ablations=[], key="k", claims=rows)]
    assert any(c.startswith(COMMAND) for c in _commands(with_rates, []))
    with_rates[0].claims = []
    assert not any(c.startswith(COMMAND) for c in _commands(with_rates, []))


def test_the_reports_engine_note_keeps_its_lines():
    """The closing note's three lines (both, one, neither) stay three in Markdown and HTML."""
    from analysis.report.builder import PaperSection, _html, _markdown

    sec = PaperSection("k", "T", "A", notes=["Hold in both: a\nHold in one: b\nneither: c"])
    md = _markdown([sec], {}, [])
    assert "> Hold in both: a\n>\n> Hold in one: b\n>\n> neither: c" in md
    assert "Hold in both: a<br>Hold in one: b<br>neither: c</p>" in _html([sec], {}, [])
