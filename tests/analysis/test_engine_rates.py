"""Issues #24, #39: the robustness rates of every engine on the same inputs, stored
(data/ablations/engine_rates.csv, ``python -m analysis.engine_rates``) and shown beside the
per-engine claims rows by ``replay claims`` and the report (analysis.engines.evaluate_runs)."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis.engine_rates import (
    CATCH_SCENARIOS,
    GRASP_PATHS,
    GRASP_SCENARIOS,
    PROBES,
    TABLE,
    catch_set,
    grasp_set,
    is_probe,
    main,
    markdown,
    merge,
    owner,
    read,
    run_catch,
    run_grasp,
    scenario_for,
    variants,
    write,
)
from analysis.engines import REFERENCE, evaluate_runs, label, registered, stored_rate_rows

ROOT = Path(__file__).resolve().parents[2]
STORED = ROOT / "data" / "ablations" / f"{TABLE}.csv"


@pytest.fixture(scope="module")
def stored():
    rows = read(STORED)
    assert rows, f"no stored table: run python -m analysis.engine_rates ({STORED})"
    return rows


def test_the_stored_table_runs_every_engine_on_the_same_inputs(stored):
    """Every registered engine (and each probe) on each set's inputs, those of the reference."""
    sets = dict.fromkeys(r["set"] for r in stored)
    assert {s.split(":")[0] for s in sets} == set(CATCH_SCENARIOS) | set(GRASP_SCENARIOS)
    labels = {r["engine"] for r in stored}
    assert {label(e) for e in registered()} <= labels, "run: python -m analysis.engine_rates"
    for s in sets:
        cases = {
            e: [r["case"] for r in stored if r["set"] == s and r["engine"] == e] for e in labels
        }
        ref = cases[label(REFERENCE)]
        assert len(ref) >= 20 and len(set(ref)) == len(ref), s
        assert all(c == ref for c in cases.values() if c), s
    for name in GRASP_SCENARIOS:
        assert grasp_set(name, len(GRASP_PATHS)) in sets
    for r in stored_rate_rows("namiki2003", STORED) + stored_rate_rows("namiki1999", STORED):
        if "engines part" in r.note:  # a probe says what decides it
            assert "; probe " in r.note, r


def test_no_stored_run_flags_success_that_its_criterion_rejects(stored):
    for r in stored:
        assert r["reason"], r
        # the grasp's flag never beats the physics, but where the criterion judges the first
        # grasp (released before 0.5 s) and the rig's flag a later one held (Drake's box, seed
        # 225 at 0.3 m/s: tests/plants/drake_arm/test_grasp_drake.py)
        assert r["success"] or not r["flag"] or r["reason"].startswith("held 0."), r
        if r["paper"] == "namiki2003":
            assert r["success"] == (r["reason"] == "caught"), r


def test_every_engine_reaches_the_bar_or_a_probe_says_why(stored):
    """Issue #24's and #39's done-when: >= 90 % in each engine on the perturbed throws and the
    unseen human paths, side by side on the same inputs; where an engine misses it on a set of
    the scenarios the papers run (catch_optimised, the grasps) a probe of that engine says what
    decides it."""
    rows = stored_rate_rows("namiki2003", STORED) + stored_rate_rows("namiki1999", STORED)
    print("\n" + markdown(stored))
    assert len(rows) == len(CATCH_SCENARIOS) + len(GRASP_SCENARIOS)
    engines = [label(e) for e in registered()]
    for r in rows:
        assert r.measured.startswith(f"{engines[0]}: "), r
        assert all(f"{e}: " in r.measured for e in engines), r
        assert "%]" in r.measured and "engine_rates.csv" in r.note, r  # interval, source
        # a test the papers did not make, against a project target: shown, never counted; the
        # target is in the note, "paper states" holds what the paper states (issue #38)
        assert r.kind == "extension" and "issue #24" in r.note, r
        assert "90 %" not in r.stated and "issue" not in r.stated, r
        if r.quantity.startswith(("catch_optimised", "grasp_")) and r.status != "reproduced":
            parted = r.note.split(";")[0]
            missing = [e for e in engines if f"{e} differs" in parted]
            assert missing and all(f"probe {e}, " in r.note for e in missing), r


def test_the_stored_runs_are_this_codes(tmp_path, stored):
    """The first throw and the first human path again, in every registered engine: the same
    verdicts as stored."""
    fresh = run_catch(1, names=CATCH_SCENARIOS[:1]) + run_grasp(
        GRASP_PATHS[:1], names=GRASP_SCENARIOS[-1:]
    )
    assert {r["engine"] for r in fresh} >= {label(e) for e in registered()}
    n = sum(r["set"].startswith(CATCH_SCENARIOS[0]) and r["engine"] == "PyBullet" for r in stored)
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


def test_a_probe_runs_its_engine_with_its_setting_on_the_same_throw(stored):
    """One throw of catch_initial in MuJoCo and in its probe (mj_solref): the stored verdicts."""
    (probe,) = PROBES["catch_initial"]
    assert probe[0] == "mujoco"
    fresh = run_catch(1, names=("catch_initial",), engines=("mujoco",))
    assert [r["engine"] for r in fresh] == ["MuJoCo", f"MuJoCo, {probe[1]}"]
    n = sum(r["set"].startswith("catch_initial") and r["engine"] == "PyBullet" for r in stored)
    for r in fresh:
        old = next(
            o
            for o in stored
            if o["set"] == catch_set("catch_initial", n)
            and o["engine"] == r["engine"]
            and o["case"] == r["case"]
        )
        assert (old["success"], old["reason"]) == (r["success"], r["reason"]), (old, r)


def test_an_engine_runs_as_its_twin_else_by_the_engine_field():
    assert scenario_for("catch_optimised", REFERENCE) == ("catch_optimised", ())
    assert scenario_for("catch_optimised", "mujoco") == ("catch_optimised_mujoco", ())
    assert scenario_for("catch_optimised", "nosuch") == (
        "catch_optimised",
        ("plant.params.engine.type=nosuch",),
    )
    # a probe of an engine not run is not run either
    assert [v[0] for v in variants("catch_initial", (REFERENCE,))] == ["PyBullet"]


def test_rerunning_some_engines_keeps_the_others_rows():
    def row(s, engine, case, ok=True):
        return {"set": s, "engine": engine, "case": case, "success": ok}

    stored = [
        row("a", "PyBullet", 0),
        row("a", "MuJoCo", 0),
        row("a", "MuJoCo, x", 0),
        row("b", "PyBullet", 0),
        row("b", "MuJoCo", 0),
    ]
    fresh = [row("a", "MuJoCo", 0, False), row("b", "MuJoCo", 0, False)]
    got = merge(stored, fresh, ["mujoco"])
    assert got == [stored[0], fresh[0], stored[3], fresh[1]]  # the probe's old rows go too
    assert is_probe("MuJoCo, x") and not is_probe("MuJoCo") and owner("MuJoCo, x") == "MuJoCo"
    assert merge(stored, [], ["drake"]) == stored  # an engine without rows: nothing lost


def test_the_command_refuses_an_unknown_engine(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["1", "--engine", "nosuch"])
    assert exc.value.code != 0 and "invalid choice: 'nosuch'" in capsys.readouterr().err


def _table(paper: str, oks: dict[str, list[bool]], why: str) -> list[dict]:
    """A stored table's rows of one set: ``oks`` maps an engine's label to each case's success
    (the same cases for all), a failure's reason ``why``."""
    good = "caught" if paper == "namiki2003" else "held"
    n = len(next(iter(oks.values())))
    return [
        {
            "paper": paper,
            "set": "s",
            "scenario": "catch_optimised" if paper == "namiki2003" else "grasp_hexahedron",
            "engine": engine,
            "case": f"case {i}",
            "success": ok[i],
            "reason": good if ok[i] else why,
            "flag": ok[i],
        }
        for i in range(n)
        for engine, ok in oks.items()
    ]


def test_rows_where_the_engines_part_say_why(tmp_path):
    oks = {"PyBullet": [True] * 10, "MuJoCo": [i < 6 for i in range(10)]}
    rows = _table("namiki2003", oks, "ball bounced off finger f1")
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
    every, some = note.splitlines()[:2]  # the closing note: the paper's rows and the rates
    held = [r for r in rates if r.status == "reproduced"]
    parted = [r for r in rates if r.status != "reproduced"]
    assert "grasp_sphere: q" in every and all(r.quantity in every for r in held), note
    # an engine below the bar: with every engine's verdict and the probe that says why
    assert all(r.quantity in some and "probe " in some for r in parted), note


def test_the_report_names_every_engines_version():
    from importlib import metadata

    from analysis.report.builder import _provenance

    info = _provenance("x")
    for engine in registered():  # an engine's name is its package's
        assert info[engine] == metadata.version(engine)


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


def test_three_engines_side_by_side_and_the_note_says_why(tmp_path):
    """A set where one of three engines misses the target: every engine's rate in the row, and
    the closing note lists it under "some engines" with its probe's rate (the measured why)."""
    from analysis.engines import closing_note

    oks = {"PyBullet": [True] * 10, "MuJoCo": [True] * 10, "Drake": [i < 7 for i in range(10)]}
    rows = _table("namiki1999", oks, "box slid 12 mm")
    probe = "Drake, hydroelastic contact"
    rows += [dict(r, engine=probe, success=True) for r in rows if r["engine"] == "Drake"]
    write(rows, tmp_path / "t.csv")
    (r,) = stored_rate_rows("namiki1999", tmp_path / "t.csv")
    assert r.measured.startswith("PyBullet: 10/10 = 100 %") and r.status == "differs"
    assert " ‖ MuJoCo: 10/10 = 100 %" in r.measured and " ‖ Drake: 7/10 = 70 %" in r.measured
    assert probe not in r.measured and f"probe {probe}: 10/10 = 100 %" in r.note
    note = closing_note([r]).splitlines()
    assert note[0] == "Hold in all 3 engines (0): none."
    assert note[1] == (
        "Hold in some engines only (1): s (PyBullet reproduced, MuJoCo reproduced, Drake "
        "differs (their intervals overlap: within the sampling error); "
        f"probe {probe}: 10/10 = 100 % [72–100 %])."
    )
    assert note[2] == "Hold in none (0): none."


def test_the_claims_join_the_runs_of_every_engine_present():
    """Logs of three engines (the engine from each resolved scenario): one column each."""
    from analysis.claims import Claim

    class Log:
        def __init__(self, name, engine):
            self.name, self.engine = name, engine

        def scenario(self):
            return {"paper": "namiki1999", "name": self.name}

        def scenario_config(self):
            return {"plant": {"type": "grasp_rig", "params": {"engine": {"type": self.engine}}}}

    def evaluate(logs):
        return [Claim(f"{n}: q", "1", str(len(n)), "reproduced") for n in logs]

    logs = {
        f"grasp_sphere{s}": Log(f"grasp_sphere{s}", e)
        for s, e in (("", "pybullet"), ("_mujoco", "mujoco"), ("_drake", "drake"))
    }
    rows, note = evaluate_runs(evaluate, logs)
    q = next(r for r in rows if r.quantity == "grasp_sphere: q")
    assert q.measured == f"PyBullet: 12 ‖ MuJoCo: 12 ‖ {label('drake')}: 12"
    assert note.startswith("Hold in all 3 engines") and "grasp_sphere: q" in note.splitlines()[0]


def test_a_run_with_its_engine_set_joins_its_scenarios_row():
    """``--set plant.params.engine.type=mujoco``: the run's label is the engine alone (its
    settings are the engine's), and the claims join it with the scenario's reference run."""
    from analysis.engines import split_logs
    from analysis.runs import differences

    ref = {"plant.type": "arm_rig", "plant.params.hand_max_torque": 1.0}
    stored = dict(ref, **{"plant.params.engine.type": "mujoco", "plant.params.engine.x": 1})
    assert differences(stored, ref) == ["engine mujoco"]
    assert differences(dict(stored, **{"plant.params.hand_max_torque": 2.0}), ref) == [
        "engine mujoco",
        "hand max torque 2",
    ]

    class Log:
        def __init__(self, engine):
            self.engine = engine

        def scenario(self):
            return {"name": "catch_initial"}

        def scenario_config(self):
            return {"plant": {"type": "arm_rig", "params": {"engine": {"type": self.engine}}}}

    logs = {
        "catch_initial": Log("pybullet"),
        "catch_initial (engine mujoco)": Log("mujoco"),
        "catch_initial (engine mujoco, seed 3)": Log("mujoco"),
    }
    groups = split_logs(logs)
    assert list(groups["MuJoCo"]) == ["catch_initial", "catch_initial (engine mujoco, seed 3)"]
    assert list(groups["PyBullet"]) == ["catch_initial"]


def test_an_engine_whose_rates_are_not_stored_is_said_not_run(tmp_path):
    """Logs of an engine the stored table lacks: its rate "not run", the row not compared (it
    does not "hold in all 3" on two engines' rates)."""
    from analysis.engines import closing_note

    rows = _table("namiki2003", {"PyBullet": [True] * 10, "MuJoCo": [True] * 10}, "")
    write(rows, tmp_path / "t.csv")
    (r,) = stored_rate_rows("namiki2003", tmp_path / "t.csv", ["PyBullet", "MuJoCo", "Drake"])
    assert r.measured.endswith(" ‖ Drake: not run") and r.status == "reproduced", r
    assert "engines part" not in r.note, r
    note = closing_note([r]).splitlines()
    assert note[0] == "Hold in all 3 engines (0): none."
    assert note[-1] == "Run in some engines only, not compared: 1 rows."
    (two,) = stored_rate_rows("namiki2003", tmp_path / "t.csv")
    assert "not run" not in two.measured and closing_note([two]).startswith(
        "Hold in both engines (1): s."
    )
