"""Any sweep's results read like results: ``DIR/summary.csv`` gives each cell (the varied
parameters but the seed) its runs, successes, rate and Wilson 95 % interval, and the variants
that could not run apart; ``sweep.lock`` is gone when the sweep ends."""

from __future__ import annotations

import pytest

from replay.sweep.engine import run_sweep
from replay.sweep.results import wilson
from replay.sweep.spec import from_options
from replay.sweep.table import read_table
from replay.sweep.variants import expand


def test_wilson_matches_its_closed_form_values():
    # (Wilson 1927; e.g. Newcombe 1998, Table I: 0/10 -> 0-0.2775, 10/10 -> 0.7225-1)
    assert wilson(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)
    assert wilson(10, 10) == pytest.approx((0.7225, 1.0), abs=1e-4)
    lo, hi = wilson(15, 148)
    assert (lo, hi) == pytest.approx((0.0624, 0.1605), abs=1e-4)
    assert wilson(0, 0) == (0.0, 1.0)


def test_a_sweep_writes_each_cell_s_rate_with_its_interval(toy_yaml, tmp_path):
    grid = ["plant.params.blow_up_at=-1,0.3", "plant.params.mass=2,-1", "seed=1,2,3"]
    variants = expand(toy_yaml, from_options(grid, [], None), 0, version="test")
    out = tmp_path / "sweep"
    run_sweep(variants, out, workers=2, keep_logs=False, progress=False)
    assert sorted(p.name for p in out.iterdir()) == ["summary.csv", "table.csv"]
    cells = {
        (c["plant.params.blow_up_at"], c["plant.params.mass"]): c
        for c in read_table(out / "summary.csv")
    }
    assert len(cells) == 4 and all("seed" not in c for c in cells.values())
    table = read_table(out / "table.csv")
    for (blow, mass), c in cells.items():
        mine = [
            r
            for r in table
            if (r["plant.params.blow_up_at"], r["plant.params.mass"]) == (blow, mass)
        ]
        if mass == "-1" or blow == "0.3":  # invalid, or a NaN (an error): no outcome, no rate
            assert all(r["reason"].startswith(("invalid", "error")) for r in mine)
            assert (c["runs"], c["not_run"], c["rate"]) == ("0", "3", "")
            continue
        ok = sum(r["success"] == "True" for r in mine)
        assert (int(c["runs"]), int(c["successes"]), c["not_run"]) == (3, ok, "0")
        lo, hi = wilson(ok, 3)
        assert float(c["rate"]) == pytest.approx(ok / 3, abs=1e-3)
        got = (float(c["rate_lo_95"]), float(c["rate_hi_95"]))
        assert got == pytest.approx((lo, hi), abs=1e-3) and lo > 0.4  # (3/3: 0.44-1)


@pytest.mark.parametrize(
    "grid",
    [
        ["plant.params.mass=1,2,4", "seed=1,2"],  # one numeric axis: the x axis
        ["plant.params.mass=1,2", "plant.params.blow_up_at=-1,5", "seed=1"],  # cells named
    ],
)
def test_any_sweep_draws_its_cells_rates(toy_yaml, tmp_path, grid):
    from click.testing import CliRunner

    from replay.cli import main

    out = tmp_path / "sweep"
    args = ["sweep", str(toy_yaml), *[a for g in grid for a in ("--grid", g)], "-o", str(out)]
    r = CliRunner().invoke(main, [*args, "--no-logs", "-q", "--workers", "1"])
    assert r.exit_code == 0, r.output
    assert len(r.output.strip().splitlines()) == 1  # (the summary line: the plot says nothing)
    assert (out / "summary.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"success rate" in (out / "summary.svg").read_bytes()


def test_a_summary_csv_of_the_users_is_never_replaced(toy_yaml, tmp_path):
    """``-o`` at a folder holding the user's own ``summary.csv`` (or a link named so): the sweep
    stops before running anything, the file as it was; its own earlier summary it rewrites."""
    from replay.sweep.table import TableError

    variants = expand(toy_yaml, from_options(["seed=1,2"], [], None), 0, version="test")
    out = tmp_path / "sweep"
    out.mkdir()
    mine = out / "summary.csv"
    mine.write_text("my,notes\n1,2\n")
    with pytest.raises(TableError, match="not a sweep's summary"):
        run_sweep(variants, out, workers=1, keep_logs=False, progress=False)
    assert mine.read_text() == "my,notes\n1,2\n" and not (out / "table.csv").exists()
    mine.unlink()
    mine.symlink_to(tmp_path / "elsewhere.csv")
    with pytest.raises(TableError, match="symbolic link"):
        run_sweep(variants, out, workers=1, keep_logs=False, progress=False)
    mine.unlink()
    run_sweep(variants, out, workers=1, keep_logs=False, progress=False)
    first = mine.read_text()
    run_sweep(variants, out, workers=1, keep_logs=False, progress=False)  # its own: rewritten
    assert mine.read_text() == first and first.startswith("runs,successes,rate")
