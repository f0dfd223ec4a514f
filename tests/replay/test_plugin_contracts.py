"""Every registered plug-in keeps the contract of its kind (as dm_control's ``domains_test`` and
robosuite's ``test_all_environments`` do for theirs), parametrised over the registry, so a new
plant, sensor or controller is checked by being registered:

- a shipped scenario uses it (the first in name order is its test scenario);
- that scenario runs a short while through the runner: a plant's spec is its ``spec_type``, its
  truth topics are in the log and the run ends with a physics verdict; a sensor's topic is in the
  log; a controller's (or task's) ``reads`` are all published in the run.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import replay
from replay import registry
from replay.resources import scenario_dir
from replay.scenario import load_scenario

DURATION = 0.15  # s simulated: every loop runs many times, and the thrown ball is in view (0.1 s)


@functools.cache
def _shipped() -> dict[str, object]:
    return {p.stem: load_scenario(p) for p in sorted(scenario_dir().glob("*.yaml"))}


def _used(sc) -> set[tuple[str, str]]:
    """(kind, type) of every plug-in a scenario names."""
    out = {("plant", sc.plant.type)}
    out |= {("sensor", s.type) for s in sc.sensors.values()}
    if sc.controller is not None:
        out.add(("controller", sc.controller.type))
    out |= {("controller", t.type) for t in (sc.tasks or {}).values()}
    return out


def _scenario_of(kind: str, name: str) -> str:
    users = [n for n, sc in _shipped().items() if (kind, name) in _used(sc)]
    assert users, f"no shipped scenario uses the {kind} {name!r}: it is never run by the suite"
    return users[0]


@functools.cache
def _short_run(scenario: str):
    return replay.run(scenario, set={"timing.duration": DURATION})


# plant types kept for the logs made before the engine field (plant.params.engine): no shipped
# scenario names them; tests/plants/mujoco_arm builds and runs them directly
FOR_OLD_LOGS = {("plant", "mujoco_arm"), ("plant", "mujoco_grasp")}


def _plugins(kind: str) -> list[str]:
    return sorted(
        n
        for n in registry.names(kind)
        if not registry.is_import_path(n) and (kind, n) not in FOR_OLD_LOGS
    )


@pytest.mark.parametrize("name", _plugins("plant"))
def test_every_plant_runs_with_its_truth_and_a_verdict(name):
    cls = registry.load("plant", name)
    scenario = _scenario_of("plant", name)
    sc = _shipped()[scenario]
    plant = cls(sc.plant.params, dt=1.0 / sc.timing.physics_rate, rng=np.random.default_rng(0))
    try:
        assert isinstance(plant.spec(), cls.spec_type), (name, type(plant.spec()))
        truth = plant.truth(0.0)
    finally:
        plant.close()
    run = _short_run(scenario)
    missing = [t for t in truth if not run.topics.get(t)]
    assert truth and not missing, (scenario, missing)
    assert run.outcome is not None and isinstance(run.outcome.get("success"), bool), scenario


@pytest.mark.parametrize("name", _plugins("sensor"))
def test_every_sensor_publishes_its_topic(name):
    scenario = _scenario_of("sensor", name)
    sc = _shipped()[scenario]
    cls = registry.load("sensor", name)
    topics = {cls.topic_for(s.params) for s in sc.sensors.values() if s.type == name}
    run = _short_run(scenario)
    assert topics and all(run.topics.get(t) for t in topics), (scenario, topics, run.topics)


@pytest.mark.parametrize("name", _plugins("controller"))
def test_every_controller_is_fed_what_it_reads(name):
    scenario = _scenario_of("controller", name)
    cls = registry.load("controller", name)
    run = _short_run(scenario)
    unfed = [t for t in cls.reads if not run.topics.get(t)]
    assert not unfed, (scenario, unfed)
    assert run.topics.get("/events") is not None


def test_the_contract_sees_an_unused_plugin():
    registry.register("sensor", "contract_probe_unused", object)
    try:
        with pytest.raises(AssertionError, match="no shipped scenario uses"):
            _scenario_of("sensor", "contract_probe_unused")
    finally:
        registry._registered["sensor"].pop("contract_probe_unused")
