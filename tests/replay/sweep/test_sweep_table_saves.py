"""A sweep rewrites its table after a finished variant only while that costs at most SAVE_SHARE
of its time (else a sweep of thousands of variants is quadratic in its table), and always at the
end: every row is there."""

from __future__ import annotations

import time

from replay.sweep import engine
from replay.sweep.engine import run_sweep
from replay.sweep.spec import from_options
from replay.sweep.table import read_table
from replay.sweep.variants import expand


def _sweep(toy_yaml, tmp_path, monkeypatch, write_cost: float) -> tuple[int, int]:
    writes = []
    write = engine.write_table

    def slow_write(*args, **kw):
        time.sleep(write_cost)
        writes.append(1)
        return write(*args, **kw)

    monkeypatch.setattr(engine, "write_table", slow_write)
    spec = from_options(["seed=1,2,3,4,5,6"], [], None)
    variants = expand(toy_yaml, spec, 0, version="test")
    out = tmp_path / f"cost{write_cost}"
    summary = run_sweep(variants, out, workers=1, keep_logs=False, progress=False)
    assert summary.ran == 6
    assert sorted(r["seed"] for r in read_table(out / "table.csv")) == list("123456")
    return len(writes), summary.ran


def test_a_costly_table_is_written_less_often_and_at_the_end(toy_yaml, tmp_path, monkeypatch):
    writes, ran = _sweep(toy_yaml, tmp_path, monkeypatch, write_cost=0.3)  # (6 s a variant)
    assert writes <= 3  # (before the variants, perhaps once among them, at the end)


def test_a_cheap_table_is_written_after_each_variant(toy_yaml, tmp_path, monkeypatch):
    monkeypatch.setattr(engine, "SAVE_SHARE", 1e6)  # (any cost is within the share)
    writes, ran = _sweep(toy_yaml, tmp_path, monkeypatch, write_cost=0.0)
    assert writes >= ran + 1
