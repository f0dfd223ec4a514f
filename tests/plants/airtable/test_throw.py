"""The air table's seeded random throw (``plant.params.throw``): drawn from the run's seed,
said in a ``throw`` event, within its ranges, and absent from the resolved scenario while off."""

from __future__ import annotations

import math

import numpy as np
import pytest

from analysis.stick.throws import random_throw
from plants.airtable import AirTablePlant, Params, ThrowParams
from plants.airtable.throw import draw
from replay.params import ParamError

DT = 1.0 / 3000.0


def _plant(seed: int, **throw) -> AirTablePlant:
    p = Params()
    p.throw = ThrowParams(random=True, **throw)
    return AirTablePlant(p, dt=DT, rng=np.random.default_rng(seed))


def _state(plant: AirTablePlant) -> tuple:
    b = plant.stick_body
    return (*b.position, b.angle, *b.velocity, b.angular_velocity)


def test_the_seed_draws_the_throw_and_the_event_says_it():
    a, b, a2 = _plant(1), _plant(2), _plant(1)
    assert _state(a) == _state(a2)
    assert not np.allclose(_state(a), _state(b))
    (ev,) = [e for e in a.pop_events() if e.kind == "throw"]
    x, y, theta, vx, vy, omega = _state(a)
    assert ev.data["x"] == pytest.approx(x) and ev.data["omega"] == pytest.approx(omega)
    assert ev.data["speed"] == pytest.approx(math.hypot(vx, vy))


@pytest.mark.parametrize("seed", range(12))
def test_a_throw_stays_in_its_ranges_and_crosses_the_pass_line(seed):
    p = ThrowParams(random=True)
    t = draw(np.random.default_rng(seed), p)
    speed = math.hypot(t["vx"], t["vy"])
    assert p.speed[0] <= speed <= p.speed[1]
    assert p.spin[0] <= abs(t["omega"]) <= p.spin[1]
    heading = math.atan2(t["vx"], -t["vy"])
    assert p.heading[0] - 1e-12 <= heading <= p.heading[1] + 1e-12
    t_pass = (p.pass_y - t["y"]) / t["vy"]  # when the centre reaches the pass line
    assert p.pass_time[0] - 1e-12 <= t_pass <= p.pass_time[1] + 1e-12
    assert p.pass_x[0] - 1e-12 <= t["x"] + t["vx"] * t_pass <= p.pass_x[1] + 1e-12


def test_fixed_levels_and_the_audit_draw_the_same_throws():
    t = draw(np.random.default_rng(5), ThrowParams(speed=[1.6, 1.6], spin=[20.0, 20.0]))
    assert math.hypot(t["vx"], t["vy"]) == pytest.approx(1.6) and abs(t["omega"]) == 20.0
    # analysis.stick.throws draws its audit throws with the plant's function
    th = random_throw(np.random.default_rng(7))
    assert (th.x, th.omega) == tuple(
        draw(np.random.default_rng(7), ThrowParams())[k] for k in ("x", "omega")
    )


def test_off_by_default_and_left_out_of_the_resolved_scenario():
    from replay.scenario import load_scenario
    from replay.scenario.loader import resolved_yaml
    from replay.resources import scenario_dir

    plant = AirTablePlant(Params(), dt=DT)
    assert not [e for e in plant.pop_events() if e.kind == "throw"]
    sc = load_scenario(scenario_dir() / "stick_3step.yaml")
    assert "throw" not in resolved_yaml(sc)
    on = load_scenario(scenario_dir() / "stick_3step.yaml", sets=["plant.params.throw.random=true"])
    assert "throw:" in resolved_yaml(on) and "pass_time" in resolved_yaml(on)


def test_a_reversed_range_is_refused():
    with pytest.raises(ParamError):
        ThrowParams(speed=[1.4, 0.8])
