"""The ablations' sweep files (sweeps/*.yaml): they load, vary real fields, carry the throws that
analysis/catching/throws.py derives, and their plots and sentences come from their tables."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from analysis.catching.throws import release
from replay.sweep import ablations
from replay.sweep.table import read_table
from replay.sweep.variants import check_keys, expand
from replay.sweep.worker import load_function

NAMES = ablations.names()


@functools.cache
def _variants(name: str) -> list:
    """The sweep file's variants, expanded once for the module (catch_rate's 840 take ~7 s)."""
    sf = ablations.load(name)
    return expand(sf.scenario, sf.spec, sf.seed, sets=sf.sets, version="test")


def test_there_are_catching_stick_and_grasping_ablations():
    assert {
        "catch_rate",
        "catch_throw_speed",
        "catch_arm_limits",
        "stick_friction",
        "stick_vision",
        "grasp_loops",
    } <= set(NAMES)


def test_grasp_loops_slows_every_loop_together(project_root):
    """Each loop period sets every task and the vision chip to the same rate (latency one frame),
    each rate a whole number of 1 kHz physics steps, periods 1 to 33 ms, and the gain rule of
    the head, arm and hand tasks to that period (gain_rule.py); >= 2 motions, >= 20 seeds."""
    from replay.scenario.loader import load_scenario

    sf = ablations.load("grasp_loops")
    sc = load_scenario(sf.scenario)
    (axis,) = [a for a in sf.spec.grid if a.name == "loop_period_ms"]
    periods = [float(label) for label in axis.labels]
    assert periods == [1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 33.0]
    for period, sets in zip(periods, axis.values):
        rates = {k for k in sets if k.startswith("tasks.") and k.endswith(".rate")}
        assert rates == {f"tasks.{t}.rate" for t in sc.tasks}
        np.testing.assert_allclose([sets[k] for k in rates], 1e3 / period, rtol=1e-9)
        assert sets["sensors.chip.rate"] == pytest.approx(1e3 / period, rel=1e-9)
        assert sets["sensors.chip.latency"] == pytest.approx(period * 1e-3, rel=1e-9)
        for task in ("head", "arm", "hand"):
            assert sets[f"tasks.{task}.params.gain_period"] == pytest.approx(period * 1e-3)
        steps = sc.timing.physics_rate * period * 1e-3
        assert steps == pytest.approx(round(steps), abs=1e-6)
    (motion,) = [a for a in sf.spec.grid if a.name == "motion"]
    assert len(motion.values) >= 2
    for label, sets in zip(motion.labels, motion.values):
        assert sets["plant.params.human_speed"] == pytest.approx(float(label))
    (seeds,) = [a for a in sf.spec.grid if a.name == "seed"]
    assert len(seeds.values) >= 20


@pytest.mark.parametrize("name", NAMES)
def test_sweep_file_expands_into_valid_variants(project_root, name):
    sf = ablations.load(name)
    check_keys(sf.scenario, sf.spec, sf.sets)
    variants = _variants(name)
    assert len(variants) >= 5
    assert not [v.error for v in variants if v.error]
    assert len({v.key for v in variants}) == len(variants)
    for ref in (sf.plot, sf.summary) + ((sf.metrics,) if sf.metrics else ()):
        assert callable(load_function(ref))
    assert sf.caption and sf.paper


def _throws(sf):
    for axis in sf.spec.grid:
        if axis.values and isinstance(axis.values[0], dict):
            for label, sets in zip(axis.labels, axis.values):
                if "plant.params.object_position" in sets:
                    yield label, sets


@pytest.mark.parametrize(
    "name",
    [n for n in NAMES if n.startswith("catch_") and n not in ("catch_rate", "catch_optimisation")],
)  # (their perturbed throws: tests/analysis/test_catch_rate.py, test_ablation_catch_opt.py)
def test_throws_are_the_derived_ones(name):
    sf = ablations.load(name)
    for label, sets in _throws(sf):
        speed = float(label.split()[0])
        offset = (0.0, 0.05, 0.0) if "+5 cm y" in label else (0.0, 0.0, 0.0)
        pos, vel = release(speed, offset)
        np.testing.assert_allclose(sets["plant.params.object_position"], pos, atol=2e-5)
        np.testing.assert_allclose(sets["plant.params.object_velocity"], vel, atol=3e-5)


@pytest.mark.parametrize("name", NAMES)
def test_plot_and_sentence_from_the_stored_table(name, tmp_path):
    sf = ablations.load(name)
    table = ablations.STORED_DIR / f"{name}.csv"
    assert table.is_file(), f"no stored table: run `replay ablate {name} --store`"
    rows = read_table(table)
    assert len(rows) == len(_variants(name))
    paths = ablations.plot(sf, table, tmp_path)
    assert [p.suffix for p in paths] == [".png", ".svg"] and all(p.stat().st_size for p in paths)
    sentence = load_function(sf.summary)(rows)
    assert sentence.endswith(".") and len(sentence) > 20
