"""The stick's condition sweeps (sweeps/stick_*.yaml) and their reading
(analysis/stick/ablations.py): the metrics from the truth, the eq.-29 check, the interval tie, the
thesis verdict, and the sweep files' fairness rules."""

from __future__ import annotations

import pytest

from analysis.stick import ablations as ab
from replay.sweep import ablations

STICK_SWEEPS = ("stick_conditions", "stick_factors", "stick_workspace", "stick_vision")


@pytest.fixture(scope="module")
def default_run(tmp_path_factory):
    """stick_3step as shipped (~0.5 s of CPU) and its log."""
    from replay.log import LogReader
    from replay.runner import Runner
    from replay.resources import scenario_dir
    from replay.scenario import load_scenario

    out = tmp_path_factory.mktemp("stick") / "run.mcap"
    Runner(load_scenario(scenario_dir() / "stick_3step.yaml")).run(out)
    return LogReader(out)


def test_metrics_read_the_truth(default_run):
    m = ab.run_metrics(default_run)
    events = default_run.events()
    (second,) = [
        e for e in events if e["kind"] == "collision" and e["data"]["planned"]["index"] == 2
    ]
    assert m["omega_eq29"] == second["data"]["omega_after"]
    # the paper's m, I, e put r_x,2 beyond the stick: clamped, spin left (eq. 29 fails)
    assert m["clamped_eq29"] and abs(m["omega_eq29"]) > ab.EQ29_TOL
    (capture,) = [e for e in events if e["kind"] == "capture"]
    (outcome,) = [e for e in events if e["kind"] == "outcome"]
    assert m["t_capture_declared"] == capture["t"]
    # the run's capture time (the plant's) precedes the method's belief and its declaration
    assert outcome["data"]["t_capture"] < outcome["data"]["t_capture_method"] < capture["t"]
    assert m["in_reach"] is True and m["fps"] == 300.0
    assert 0.0 < m["base_speed_max"] <= 1.0 + 1e-6  # the slider's 1.0 m/s per axis
    assert m["base_x_max"] <= 0.2 + 1e-9 and m["base_y_max"] <= 0.2 + 1e-9
    assert "v0" not in m  # no random throw: no throw event


def _row(captured: bool, **kw) -> dict:
    return {"m.captured": str(captured), "x.in_reach": "True", **kw}


def test_capture_is_the_plants_and_undecided_is_in_reach():
    assert ab.truth_captured(_row(True, success="False"))
    assert not ab.truth_captured({"success": "True", "e.capture": "1", "m.captured": "False"})
    assert ab.undecided(_row(False)) and not ab.undecided(_row(True))
    assert not ab.undecided({"m.captured": "False", "x.in_reach": "False"})
    assert ab.eq29_holds({"x.omega_eq29": "0.3"}) and not ab.eq29_holds({"x.omega_eq29": "-3"})
    assert not ab.eq29_holds({"x.omega_eq29": ""})


def test_tie_is_overlapping_wilson_intervals():
    assert ab.tie([(17, 20), (19, 20), (15, 20)])
    assert not ab.tie([(20, 20), (5, 20)])
    assert ab.rate_text(20, 20).startswith("20/20 (84-100")


def _cells(rates: dict) -> list[dict]:
    """Rows of a stick_conditions table: {(scenario, W, mu): captured of 20}."""
    rows = []
    for (sc, w, mu), k in rates.items():
        for i in range(20):
            rows.append(
                {
                    "scenario": sc,
                    "plant.params.stick.collision_width": str(w),
                    "plant.params.stick.friction": str(mu),
                    "m.captured": str(i < k),
                    "x.in_reach": "False",
                    "x.omega_eq29": "0.1",
                }
            )
    return rows


@pytest.mark.parametrize(
    "thin, wide, verdict",
    [
        ((19, 18, 19), (18, 19, 18), "holds"),
        ((19, 18, 19), (18, 10, 2), "holds only when the width is negligible"),
        ((19, 2, 19), (18, 19, 18), "does not hold"),
    ],
)
def test_thesis_verdict_follows_the_intervals(thin, wide, verdict):
    rates = {}
    for w, ks in ((0.0, thin), (0.01, wide)):
        for mu, k in zip((0.0, 0.3, 1.0), ks):
            rates[("stick_3step", w, mu)] = k
    out = ab.thesis({name: [] for name in ab.THESIS_SWEEPS} | {"stick_conditions": _cells(rates)})
    assert out["verdict"].startswith(verdict)
    assert out["figure"].endswith(".png") and out["numbers"]["undecided runs"] == 0


def test_sweeps_vary_real_throws_at_20_seeds_a_cell():
    for name in STICK_SWEEPS:
        sf = ablations.load(name)
        assert "plant.params.throw.random=true" in sf.sets, name
        (seeds,) = [a for a in sf.spec.grid if a.name == "seed"]
        assert len(set(seeds.values)) >= 20, name
        duration = [s for s in sf.sets if s.startswith("timing.duration=")]
        assert duration and float(duration[0].split("=")[1]) >= 4.0, name


def test_vision_sweep_keeps_estimator_spans_in_seconds():
    """The fair rule of sweeps/stick_vision.yaml: window round(0.1 s f), ready after
    max(3, round(0.02 s f)) frames, detect_window max(0.04 s, latency + 3 / f); latency one
    frame; every rate divides the 3 kHz physics rate."""
    (axis,) = [a for a in ablations.load("stick_vision").spec.grid if a.name == "camera"]
    rates = set()
    for label, sets in zip(axis.labels, axis.values):
        f = float(sets["sensors.camera.rate"])
        rates.add(f)
        assert sets["sensors.camera.latency"] == pytest.approx(1.0 / f, rel=1e-6)
        assert 3000.0 / f == pytest.approx(round(3000.0 / f))
        if "seconds" in label or "both" in label:
            assert sets["controller.params.window"] == round(0.1 * f)
            assert sets.get("controller.params.min_samples", 6) == max(3, round(0.02 * f))
            want = max(0.04, 1.0 / f + 3.0 / f)
            assert sets.get("controller.params.detect_window", 0.04) == pytest.approx(
                want, rel=1e-6
            )
        else:
            assert sets["controller.params.window"] == 30 and len(sets) == 3
    assert rates == {300.0, 200.0, 100.0, 60.0, 30.0}


@pytest.mark.parametrize("name", STICK_SWEEPS)
def test_stored_table_draws_and_says_its_numbers(name, tmp_path):
    from replay.sweep.table import read_table
    from replay.sweep.worker import load_function

    path = ablations.STORED_DIR / f"{name}.csv"
    rows = read_table(path)
    sf = ablations.load(name)
    files = load_function(sf.plot)(rows, tmp_path, name)
    assert any(str(f).endswith(".png") for f in files)
    text = load_function(sf.summary)(rows)
    assert "undecided" in text and "/20 (" in text
    k, n = ab.kn(rows)
    assert n == sf.spec.count and 0.0 <= ab._wilson(k, n)[0] <= k / n


def test_thesis_says_when_the_3_step_needs_more_than_three_collisions():
    rates = {("stick_3step", w, mu): 19 for w in (0.0, 0.01) for mu in (0.0, 0.3, 1.0)}
    factors = [
        {"factor": name, "m.captured": str(i < k), "x.omega_eq29": "-3.0"}
        for name, k in (("default", 19), ("3 steps only", 3))
        for i in range(20)
    ]
    out = ab.thesis(
        {name: [] for name in ab.THESIS_SWEEPS}
        | {"stick_conditions": _cells(rates), "stick_factors": factors}
    )
    assert out["verdict"].startswith("holds only when the 3-step method may add spin-stop")
    assert out["numbers"]["3-step: default vs 3 steps only"]["3 steps only"].startswith("3/20")
    assert out["numbers"]["eq29 after step 2 (3-step)"]["default"].startswith("0/20")
