"""The scenario JSON Schema (``replay schema``) against the loader: every shipped scenario
validates, bad ones do not, and over random variations what the loader accepts the schema
accepts too (the schema may be looser: the loader also checks what JSON Schema cannot say)."""

from __future__ import annotations

import copy
import re
from pathlib import Path

import jsonschema
import numpy as np
import pytest
import yaml

from replay.scenario import ScenarioError, load_scenario, scenario_from_text, to_plain
from replay.scenario.json_schema import scenario_schema

ROOT = Path(__file__).resolve().parents[3]
SHIPPED = sorted((ROOT / "scenarios").glob("*.yaml"))


class _Yaml12Floats(yaml.SafeLoader):
    """YAML as an editor's language server reads it: ``1e-3`` is a number (YAML 1.2), as the
    scenario loader also takes it."""


_Yaml12Floats.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(\d[\d_]*\.?\d*|\.\d+)[eE][-+]?\d+$"),
    list("-+0123456789."),
)


def read(text: str):
    return yaml.load(text, Loader=_Yaml12Floats)  # noqa: S506 - a SafeLoader subclass


@pytest.fixture(scope="module")
def validator():
    schema = scenario_schema()
    jsonschema.Draft7Validator.check_schema(schema)
    return jsonschema.Draft7Validator(schema)


def errors(validator, data) -> list[str]:
    return [f"{e.json_path}: {e.message}" for e in validator.iter_errors(data)]


@pytest.mark.parametrize("path", SHIPPED, ids=[p.stem for p in SHIPPED])
def test_every_shipped_scenario_validates(validator, path):
    assert errors(validator, read(path.read_text())) == []
    # and as the loader resolved it: every default filled in, no extends
    resolved = to_plain(load_scenario(path))
    assert errors(validator, resolved) == []


BASE = """\
name: t
paper: higashimori2007
timing: {physics_rate: 3000, duration: 0.5}
plant:
  type: airtable
  params:
    stick: {mass: 0.0225, friction: 0.3}
sensors:
  camera: {type: stick_camera, rate: 300, latency: 0.0}
controller: {type: stick_3step, rate: 1000}
"""


def test_the_base_of_the_bad_cases_is_good(validator):
    assert errors(validator, read(BASE)) == []
    load_scenario_text(BASE)


def load_scenario_text(text: str):
    return scenario_from_text(text, "<test>")


@pytest.mark.parametrize(
    "change, where",
    [
        (lambda d: d.update(colour="red"), "colour"),
        (lambda d: d.pop("name"), "name"),
        (lambda d: d.update(name="../escape"), "name"),
        (lambda d: d["timing"].update(duration="fast"), "duration"),
        (lambda d: d["timing"].update(duration=-1.0), "duration"),
        (lambda d: d["timing"].update(physics_rate=0), "physics_rate"),
        (lambda d: d["timing"].update(physics_rate=2.5), "physics_rate"),
        (lambda d: d["plant"].update(type="no_such_plant"), "type"),
        (lambda d: d["plant"]["params"]["stick"].update(colour="red"), "colour"),
        (lambda d: d["plant"]["params"]["stick"].update(mass=-1.0), "mass"),
        (lambda d: d["plant"]["params"]["stick"].update(friction=[0.3]), "friction"),
        (lambda d: d["sensors"]["camera"].pop("rate"), "rate"),
        (lambda d: d["sensors"].update({"bad name!": d["sensors"]["camera"]}), "bad name"),
        (lambda d: d["controller"].update(type="stick_9step"), "type"),
        (lambda d: d["controller"].update(params={"no_such_param": 1}), "no_such_param"),
        (lambda d: d.pop("controller"), "controller"),
        (
            lambda d: (
                d["stop"].update(on_events="capture")
                if "stop" in d
                else d.update(stop={"on_events": "capture"})
            ),
            "on_events",
        ),
    ],
)
def test_bad_scenarios_fail_both_schema_and_loader(validator, change, where):
    data = read(BASE)
    change(data)
    found = errors(validator, data)
    assert found, f"the schema accepted a bad scenario ({where})"
    with pytest.raises(ScenarioError):
        load_scenario_text(yaml.safe_dump(data))


@pytest.mark.parametrize(
    "kind, name, ok",
    [
        ("controller", "my_controller:GoalKeeper", True),
        ("plant", "pkg.sub:Mod.Plant", True),
        ("controller", "no colon", False),
        ("controller", "a:b:c", False),
        ("controller", "x; rm -rf /:A", False),
    ],
)
def test_a_plugin_type_may_be_an_import_path(validator, kind, name, ok):
    data = read(BASE)
    data[kind]["type"] = name
    data[kind].pop("params", None)
    assert (errors(validator, data) == []) == ok, errors(validator, data)


def test_what_the_loader_takes_as_defaults_validates(validator):
    data = read(BASE)
    data["stop"] = None  # "stop:" alone: every default
    data["plant"]["params"]["stick"] = None
    assert errors(validator, data) == []
    load_scenario_text(yaml.safe_dump(data))


def test_a_bad_arm_scenario_fails(validator):
    data = read((ROOT / "scenarios/catch_optimised.yaml").read_text())
    assert errors(validator, data) == []
    data["plant"]["params"]["object_size"] = [0.05, 0.05]  # a box needs 3 extents
    assert errors(validator, data)


def test_an_extending_file_needs_nothing_but_checks_what_it_gives(validator):
    assert errors(validator, {"extends": "stick_3step.yaml"}) == []
    partial = {"extends": "stick_3step.yaml", "sensors": {"camera": {"latency": 0.01}}}
    assert errors(validator, partial) == []
    # a plug-in's params are checked once its type is known (here, given with them)
    typed = {"type": "airtable", "params": {"stick": {"mass": -1}}}
    assert errors(validator, {**partial, "plant": typed})
    bad = {"extends": "stick_3step.yaml", "plant": {"type": "airtable", "params": {"x": 1}}}
    assert errors(validator, bad)
    assert errors(validator, {"extends": "stick_3step.yaml", "timing": {"duration": "long"}})
    assert errors(validator, {"extends": "", "name": "x"})


def _numbers(node, path=()):
    """(path, value) of every number in a plain scenario."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _numbers(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _numbers(v, path + (i,))
    elif isinstance(node, (int, float)) and not isinstance(node, bool):
        yield path, node


def _set(node, path, value):
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value


N_VARIATIONS = 50  # the loader takes 0.1-0.3 s of CPU a scenario


def test_random_variations_loader_accepts_implies_schema_accepts(validator):
    """Seeded: 50 variations of the shipped scenarios, one number each scaled, negated, made
    huge or replaced by a string; whatever the loader accepts the schema must accept, and the
    schema must refuse most of what the loader refuses (its range and type checks)."""
    rng = np.random.default_rng(13)
    bases = [to_plain(load_scenario(p)) for p in SHIPPED]
    agree = accepted_by_loader = refused_by_both = refused_by_loader = 0
    for _ in range(N_VARIATIONS):
        data = copy.deepcopy(bases[rng.integers(len(bases))])
        numbers = list(_numbers(data))
        path, value = numbers[rng.integers(len(numbers))]
        kind = rng.integers(4)
        new = [value * rng.uniform(-3, 3), -value, 1e12, "x"][kind]
        if isinstance(value, int) and kind < 2:
            new = int(round(new))
        _set(data, path, new)
        schema_ok = not errors(validator, data)
        try:
            scenario_from_text(yaml.safe_dump(data, sort_keys=False), "<variation>")
            loader_ok = True
        except ScenarioError:
            loader_ok = False
        if loader_ok:
            accepted_by_loader += 1
            assert schema_ok, (path, value, new, errors(validator, data))
        else:
            refused_by_loader += 1
            refused_by_both += not schema_ok
        agree += loader_ok == schema_ok
    print(
        f"loader accepted {accepted_by_loader}, refused {refused_by_loader} "
        f"(schema refused {refused_by_both} of those); agreement {agree}/{N_VARIATIONS}"
    )
    assert accepted_by_loader >= 8 and refused_by_loader >= 8
    assert refused_by_both >= 0.8 * refused_by_loader
