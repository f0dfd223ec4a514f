"""A paper's analysis moved into its package (issue #40): an old ``analysis.<module>:<function>``
name in a stored sweep table or sweep file still loads, and the migration tool rewrites it."""

from __future__ import annotations

import importlib
import importlib.util
import runpy
from pathlib import Path

import pytest

from analysis import MOVED
from replay.sweep.worker import load_function

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("old, new", sorted(MOVED.items()))
def test_every_moved_module_is_found_at_its_new_name(old, new):
    assert importlib.util.find_spec(new) is not None
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module(old)


def test_an_old_metrics_name_loads_the_moved_function():
    from analysis.stick.ablations import run_metrics

    assert load_function("analysis.ablation_stick:run_metrics") is run_metrics


def test_an_unknown_module_is_still_an_error():
    with pytest.raises(ModuleNotFoundError):
        load_function("analysis.no_such_module:f")


def test_the_migration_rewrites_old_names_only(tmp_path):
    table = tmp_path / "t.csv"
    table.write_text(
        "index,version\n0,0.1.0+abc|analysis.ablation_catch:catch_metrics\n"
        "1,0.1.0+abc|analysis.ablation_catch_opt:effort_metrics\n2,analysis.runs:x\n",
        encoding="utf-8",
    )
    tool = runpy.run_path(str(ROOT / "tools" / "migrate_analysis_names.py"), run_name="tool")
    assert tool["main"]([str(tmp_path)]) == 0
    assert table.read_text(encoding="utf-8").splitlines()[1:] == [
        "0,0.1.0+abc|analysis.catching.ablations:catch_metrics",
        "1,0.1.0+abc|analysis.catching.ablation_opt:effort_metrics",
        "2,analysis.runs:x",
    ]


def test_no_stored_file_names_a_moved_module():
    stored = [*(ROOT / "data").rglob("*.csv"), *(ROOT / "sweeps").glob("*.yaml")]
    bad = [p.name for p in stored if any(f"{m}:" in p.read_text(encoding="utf-8") for m in MOVED)]
    assert not bad
