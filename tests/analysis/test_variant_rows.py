"""A log that changes its shipped scenario yet keeps its name (a variant standing in for the
paper's run) decides no counted row: its measured rows are shown as "other regime", verdict and
all, with a note naming what it changes; a run of the scenario as shipped is counted as before."""

from __future__ import annotations

from click.testing import CliRunner

from analysis.claims import counted
from analysis.engines import evaluate_runs
from replay import registry
from replay.cli import main
from replay.log import LogReader


def _run(out, sets=()):
    args = ["run", "stick_2step", "-q", "-o", str(out)]
    for s in sets:
        args += ["--set", s]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == 0, r.output
    return LogReader(out)


def test_rows_a_variant_decides_are_another_regime_and_not_counted(tmp_path):
    evaluate = registry.load("claims", "higashimori2007")
    shipped = _run(tmp_path / "a.mcap")
    variant = _run(tmp_path / "b.mcap", ["plant.params.initial.omega=5.0"])
    rows_a, _ = evaluate_runs(evaluate, {"stick_2step": shipped})
    rows_b, _ = evaluate_runs(evaluate, {"stick_2step": variant})
    read = {
        r.quantity
        for r in rows_a
        if r.kind == "measured" and any(m.startswith("stick_2step:") for m in r.measures)
    }
    assert read  # the paper's rows that read the 2-step run
    by_b = {r.quantity: r for r in rows_b}
    for q in read:
        assert by_b[q].kind == "other regime", q
        assert "stick_2step is a variant (" in by_b[q].note and "omega" in by_b[q].note, q
    assert counted(rows_b)[1] == counted(rows_a)[1] - len(read)


def test_the_claims_command_says_so_and_counts_without_them(tmp_path):
    _run(tmp_path / "v.mcap", ["plant.params.initial.omega=5.0"])
    r = CliRunner().invoke(main, ["claims", str(tmp_path / "v.mcap")])
    assert r.exit_code == 0, r.output
    assert "stick_2step: this log is a variant (" in r.output
    assert "not counted" in r.output and "other regime" in r.output
