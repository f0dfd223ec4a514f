"""Every registered plug-in keeps the contract of its kind (as dm_control's ``domains_test`` and
robosuite's ``test_all_environments`` do for theirs), parametrised over the registry, so a new
plant, sensor or controller is checked by being registered:

- every installed plant, sensor and controller is checked: its group's entry points and those
  the installed papers' registrations name (a plug-in a test registers in-process is not), and
  the installed groups are the ones pyproject.toml declares (a stale install would hide one);
- a shipped scenario uses it (the first in name order is its test scenario);
- that scenario runs a short while through the runner: a plant's spec is its ``spec_type``, its
  truth topics are in the log and the run ends with a physics verdict; a sensor's topic is in the
  log; a controller's (or task's) ``reads`` are all published in the run.
"""

from __future__ import annotations

import functools
import tomllib
from importlib.metadata import entry_points

import numpy as np
import pytest

import replay
from replay import registry
from replay.resources import scenario_dir
from replay.scenario import load_scenario

from conftest import ROOT

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


def _group(kind: str) -> list[str]:
    """Every installed entry point of ``kind``'s group."""
    return sorted(ep.name for ep in entry_points(group=registry.GROUPS[kind]))


def _plugins(kind: str) -> list[str]:
    """Every installed plug-in of ``kind``: its group's entry points and those the installed
    papers name (replay/papers.py), not one a test registers in this process, nor a plant type
    kept only for old logs."""
    return sorted(
        n
        for n in registry.names(kind)
        if n not in registry._registered[kind] and (kind, n) not in FOR_OLD_LOGS
    )


@pytest.mark.parametrize("kind", ["paper", "plant", "sensor", "controller"])
def test_the_contracts_cover_every_entry_point_pyproject_declares(kind):
    group = registry.GROUPS[kind]
    with open(ROOT / "pyproject.toml", "rb") as f:
        declared = tomllib.load(f)["project"]["entry-points"].get(group, {})
    assert _group(kind) == sorted(declared), f"reinstall: {group} differs from pyproject.toml"
    assert set(_group(kind)) <= set(registry.names(kind))
    assert kind == "paper" or len(_plugins(kind)) >= 3, _plugins(kind)  # the papers' own


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
