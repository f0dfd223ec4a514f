"""PyBullet's settings in the engine field (``plant.params.engine: {type: pybullet, ...}``,
plants/bullet_arm/settings.py) and the rig's plant types (``arm_rig``, ``grasp_rig``): the older
forms, PyBullet's settings flat in ``plant.params`` and the types ``bullet_arm``/``bullet_grasp``,
still load from scenarios and logs (plants/arm_rig/engine.py ``migrate_flat_settings``,
``replay.registry.current_name``), and a flat one beside another engine is refused in one line."""

from __future__ import annotations

import pytest
import yaml

from replay import registry
from replay.scenario import load_scenario, scenario_from_text
from replay.scenario.loader import resolved_yaml, to_plain
from replay.scenario.yamlio import ScenarioError


def test_a_bad_pybullet_setting_is_one_line_naming_its_path():
    with pytest.raises(ScenarioError) as info:
        load_scenario(
            "catch_optimised", ["plant.params.engine={type: pybullet, solver_iterations: 0}"]
        )
    message = str(info.value)
    assert "plant.params.engine.solver_iterations: expected a whole number >= 1" in message
    assert "\n" not in message


# ---------------------------------------------------------------- PyBullet's settings, once flat
FLAT = {"object_restitution": 0.25, "contact_stiffness": 2000.0, "solver_iterations": 30}


OLD_NAMES = {"arm_rig": "bullet_arm", "grasp_rig": "bullet_grasp"}


def _old_form(name: str) -> str:
    """The resolved text of shipped scenario ``name`` with PyBullet's settings ``FLAT`` flat in
    ``plant.params`` and the rig's plant type by its old name, as the scenarios and logs made
    before the engine field held them."""
    data = to_plain(load_scenario(name))
    data["plant"]["type"] = OLD_NAMES[data["plant"]["type"]]
    params = data["plant"]["params"]
    if params["engine"]["type"] == "pybullet":
        params.update({k: v for k, v in params.pop("engine").items() if k != "type"})
    params.update(FLAT)
    return yaml.safe_dump(data, sort_keys=False)


def test_an_old_scenario_with_pybullet_settings_flat_loads_them_into_the_engine(tmp_path):
    old = tmp_path / "old.yaml"
    old.write_text(_old_form("grasp_hexahedron"))
    plant = load_scenario(old).plant
    assert plant.type == "grasp_rig"
    assert plant.params.engine == {**load_scenario("grasp_hexahedron").plant.params.engine, **FLAT}
    logged = scenario_from_text(old.read_text(), plugins="known-only").plant
    assert (logged.type, logged.params.engine) == ("grasp_rig", plant.params.engine)
    assert "type: grasp_rig" in resolved_yaml(load_scenario(old))  # (a run's log: the new name)


def test_the_rigs_old_plant_types_are_read_as_their_names_now():
    for new, old in OLD_NAMES.items():
        assert registry.current_name("plant", old) == new and registry.known("plant", old)
        assert registry.load("plant", old) is registry.load("plant", new)
        assert registry.load("viewer_scene", old) is registry.load("viewer_scene", new)
        assert old not in registry.names("plant")  # (not listed, nor described)
    assert registry.current_name("plant", "mujoco_arm") == "mujoco_arm"  # (its own, for old logs)
    assert registry.current_name("sensor", "bullet_arm") == "bullet_arm"


def test_pybullet_settings_flat_beside_another_engine(tmp_path):
    """A log made then (every default written, PyBullet's flat ones unused) loads without them;
    a scenario file giving one with engine mujoco is refused, naming it."""
    text = _old_form("grasp_hexahedron_mujoco")
    logged = scenario_from_text(text, plugins="known-only").plant.params
    assert logged.engine == load_scenario("grasp_hexahedron_mujoco").plant.params.engine
    old = tmp_path / "old_mujoco.yaml"
    old.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(old)
    message = str(info.value)
    assert "\n" not in message and "old_mujoco.yaml:" in message
    assert "plant.params.object_restitution: a PyBullet setting, not used by engine mujoco" in (
        message
    )


def test_a_set_that_changes_the_engine_drops_the_old_engines_settings():
    own = load_scenario("grasp_hexahedron").plant.params.engine
    assert own["contact_stiffness"] == 3000.0  # (the shipped soft pads)
    drake = load_scenario("grasp_hexahedron", ["plant.params.engine.type=drake"])
    engine = drake.plant.params.engine
    assert engine["type"] == "drake" and not set(FLAT) & set(engine)
    same = load_scenario("grasp_hexahedron", ["plant.params.engine.type=pybullet"])
    assert same.plant.params.engine == own


def test_an_old_log_reads_as_its_scenario_now_in_the_analysis(tmp_path):
    """The runs' labels and `replay compare` read an old log's scenario as the loader does now
    (analysis/runs.py ``current_config``): no difference from the same run logged today."""
    from analysis import runs
    from replay.log import LogReader, LogWriter
    from replay.messages import TOPIC_SCENARIO, ScenarioInfo

    def log(name: str, text: str) -> LogReader:
        path = tmp_path / f"{name}.mcap"
        with LogWriter(path) as w:
            w.write(
                TOPIC_SCENARIO, ScenarioInfo(0.0, "grasp_hexahedron", "namiki1999", text, 0, ""), 0
            )
        return LogReader(path)

    old = log("old", _old_form("grasp_hexahedron"))
    sets = [f"plant.params.engine.{k}={v}" for k, v in FLAT.items()]
    new = log("new", resolved_yaml(load_scenario("grasp_hexahedron", sets)))
    assert old.scenario_config()["plant"]["type"] == "bullet_grasp"  # (as stored)
    assert runs.current_config(old) == runs.current_config(new)
    assert runs.current_config(old)["plant"]["type"] == "grasp_rig"
