"""replay falsify: every measured reproduced row must be flipped to "differs" by its falsifier."""

from __future__ import annotations

import pytest

from analysis.claims import Claim, Falsifier, agrees, smaller, summary
from analysis.falsify import _sets, check
from replay.log import LogReader


def _evaluate(logs):
    """A paper whose rows read a number from each 'log' (here a plain float)."""
    rows = [
        Claim(
            "a small", "< 1", f"{logs['run']:.2f}", "reproduced" if logs["run"] < 1 else "differs"
        )
    ]
    rows.append(Claim("set", "2", "2", "consistent", kind="configuration"))
    rows.append(Claim("b", "> 0", "1", "reproduced" if logs["other"] > 0 else "differs"))
    return rows


def test_a_falsifier_that_flips_its_row_passes_and_one_that_does_not_fails():
    flips = Falsifier("a small", "big", "run", {"x": 5.0})
    runs = []

    def run(f):
        runs.append(f.name)
        return f.overrides["x"]

    out = check(_evaluate, {"run": 0.5, "other": 1.0}, [flips], run)
    by = {(v.row, v.variant): v for v in out}
    assert by[("a small", "big")].ok and by[("a small", "big")].status == "differs"
    assert not by[("b", "")].ok  # reproduced without a falsifier: a failure
    assert runs == ["big"]
    weak = Falsifier("a small", "still_small", "run", {"x": 0.7})
    out = check(_evaluate, {"run": 0.5, "other": 1.0}, [weak], run)
    assert not next(v for v in out if v.variant == "still_small").ok
    assert "FAIL" in next(v for v in out if v.variant == "still_small").line()


def test_a_row_that_does_not_agree_at_baseline_is_not_run():
    f = Falsifier("a small", "big", "run", {"x": 5.0})
    out = check(
        _evaluate,
        {"run": 3.0, "other": 1.0},
        [f, Falsifier("b", "neg", "other", {"x": -1.0})],
        lambda f: f.overrides["x"],
    )
    v = next(v for v in out if v.variant == "big")
    assert v.ok and v.status == "" and v.baseline == "differs"
    assert all(v.ok for v in out)


def test_overrides_become_set_assignments():
    assert _sets({"a.b": [0.005, 0.0], "c": True, "d": 2.0}) == [
        "a.b=[0.005, 0.0]",
        "c=true",
        "d=2.0",
    ]


def test_only_measured_rows_are_reproduced_and_counted():
    with pytest.raises(ValueError):
        Claim("x", "1", "1", "reproduced", kind="configuration")
    assert agrees(True) == "consistent" and agrees(False) == "differs"
    assert smaller(2.2851, 2.2865, tol=0.01 * 2.2865) == "tie"
    assert smaller(1.0, 2.0, tol=0.1) == "reproduced" and smaller(2.0, 1.0, 0.1) == "differs"
    rows = _evaluate({"run": 0.5, "other": 1.0})
    text = summary(rows, [Falsifier("a small", "big", "run")])
    assert text.startswith("1 of 2 measured rows reproduced")
    assert "1 more agree but have no falsifier" in text and "1 configuration row" in text


def test_replay_falsify_flips_every_reproduced_row_of_the_stick_and_catch_tables(tmp_path):
    """The whole check, as CI runs it: the papers' default scenarios, then every falsifier."""
    from click.testing import CliRunner

    from replay.cli import main

    res = CliRunner().invoke(
        main, ["falsify", "higashimori2007", "namiki2003", "--keep", str(tmp_path)]
    )
    assert res.exit_code == 0, res.output
    lines = [ln for ln in res.output.splitlines() if ln.startswith(("ok", "FAIL"))]
    assert lines and not [ln for ln in lines if ln.startswith("FAIL")]
    assert any("catch_optimised: ball caught | enforced_limits" in ln for ln in lines)
    assert any("translation after collision 1 | width10" in ln for ln in lines)
    # every measured row reproduced at baseline has its falsifier line, flipped to "differs"
    from analysis import catch_claims, stick_claims

    for paper, module in (("higashimori2007", stick_claims), ("namiki2003", catch_claims)):
        logs = {p.stem: LogReader(p) for p in (tmp_path / paper / "baseline").glob("*.mcap")}
        rows = module.evaluate(logs)
        for r in rows:
            if r.kind == "measured" and r.status == "reproduced":
                assert any(
                    ln.startswith(f"ok    {r.quantity} |") and "-> differs" in ln for ln in lines
                ), r.quantity
