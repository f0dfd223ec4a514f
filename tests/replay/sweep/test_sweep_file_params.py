"""A sweep's variant runs from its resolved text, which does not say where the scenario file was:
its relative ``*_file`` parameters (the catching mapping's ``alpha_file``) must still resolve
against the scenario's folder, not the worker's cwd. (They resolved against the cwd: every catch
variant silently re-optimised its mapping instead of reading the file it named.)"""

from __future__ import annotations

import pytest

from conftest import ROOT
from replay.control.catching import problem
from replay.sweep.spec import from_options
from replay.sweep.variants import expand
from replay.sweep.worker import run_variant

CATCH = ROOT / "scenarios" / "catch_optimised.yaml"


def test_a_variant_reads_the_alpha_file_its_scenario_names(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)  # (run_variant changes the cwd: restored after the test)
    spec = from_options(["seed=0"], [], None)
    (variant,) = expand(CATCH, spec, 0, sets=["timing.duration=0.01"], version="test")
    assert variant.file_dirs["controller"] == str(CATCH.parent)

    def no_optimising(*args, **kwargs):
        raise AssertionError("the mapping was optimised, not read from its alpha_file")

    monkeypatch.setattr(problem.CatchingProblem, "solve", no_optimising)
    task = {
        "key": variant.key,
        "index": 0,
        "resolved": variant.resolved,
        "file_dirs": variant.file_dirs,
        "error": "",
        "log": "",
        "cwd": str(tmp_path),  # (a worker anywhere: ../data/... from here is nothing)
        "metrics": "",
    }
    row = run_variant(task)
    assert "error" not in row["reason"], row["reason"]
    assert row["t_end"] == pytest.approx(0.01)


def _file_settings(sf) -> set[tuple[str, str]]:
    """Every (key, value) a sweep file sets on a ``*_file`` parameter, on its axes or for all."""
    found = set()
    for text in sf.sets:
        key, _, value = text.partition("=")
        found.add((key, value))
    for axis in sf.spec.grid:
        for value in axis.values:
            pairs = value.items() if isinstance(value, dict) else [(axis.name, value)]
            found.update((k, str(v)) for k, v in pairs)
    return {(k, v) for k, v in found if k.endswith("_file") and v}


def test_every_shipped_sweeps_files_exist():
    """A file a sweep names that does not exist would be recomputed silently (the catching
    mapping optimises eq. 25 when its alpha_file is missing): each resolves to a file."""
    from replay.control.catching.controller import alpha_path
    from replay.scenario import load_scenario
    from replay.sweep import ablations

    checked = 0
    for name in ablations.names():
        sf = ablations.load(name)
        for key, value in sorted(_file_settings(sf)):
            sc = load_scenario(sf.scenario, sets=[f"{key}={value}"])
            assert key == "controller.params.alpha_file", (name, key)
            path = alpha_path(sc.controller.params)
            assert path is not None and path.is_file(), (name, value, path)
            checked += 1
    assert checked >= 5  # (catch_optimisation names its alpha files)
