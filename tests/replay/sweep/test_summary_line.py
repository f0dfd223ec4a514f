"""An ablation that states its own measure does not call variants that stop before the paper's
end by design "failed": its summary counts only the variants that could not run."""

from pathlib import Path

from replay.sweep.engine import SweepSummary


def _summary(reasons):
    rows = [{"index": i, "reason": r, "success": False} for i, r in enumerate(reasons)]
    return SweepSummary(len(rows), len(rows), 0, 0, len(rows), 1.0, Path("t.csv"), rows=rows)


def test_by_design_stops_are_not_failures():
    s = _summary(["stopped at the duration", "stopped at the duration"])
    assert "0 succeeded, 2 failed" in s.line()
    assert "all ran" in s.line(outcomes=False) and "failed" not in s.line(outcomes=False)


def test_variants_that_could_not_run_are_counted():
    s = _summary(["error: boom", "worker died: killed by SIGKILL", "invalid: x", "stopped"])
    assert s.not_run == 3
    assert "3 could not run" in s.line(outcomes=False)
