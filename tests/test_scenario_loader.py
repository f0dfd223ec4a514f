"""The scenario loader: strict types, clear errors with file:line:col and field path, extends, --set."""

import pytest

from replay.scenario import ScenarioError, load_scenario, resolved_yaml, scenario_from_text


def test_loads_and_fills_defaults(toy_yaml):
    sc = load_scenario(toy_yaml)
    assert sc.plant.params.mass == 2.0
    assert sc.plant.params.wall == 10.0          # default filled in
    assert sc.controller.params.kp == 100.0
    assert sc.sensors["cam"].latency == 0.02
    text = resolved_yaml(sc)
    assert "wall: 10.0" in text and "kp: 100.0" in text


def test_resolved_text_round_trips(toy_yaml):
    sc = load_scenario(toy_yaml)
    again = scenario_from_text(resolved_yaml(sc))
    assert resolved_yaml(again) == resolved_yaml(sc)


def _error(tmp_path, text, name="bad.yaml", **kw):
    p = tmp_path / name
    p.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(p, **kw)
    return str(info.value)


def test_unknown_key_names_line_and_column(tmp_path, toy_yaml):
    text = toy_yaml.read_text().replace("  params: {mass: 2.0}", "  params: {mass: 2.0, colour: 1}")
    msg = _error(tmp_path, text)
    assert "bad.yaml:8:23:" in msg and "plant.params.colour" in msg and "unknown field" in msg
    assert "mass" in msg  # lists what is expected


def test_negative_mass_is_out_of_range(tmp_path, toy_yaml):
    msg = _error(tmp_path, toy_yaml.read_text().replace("mass: 2.0", "mass: -1"))
    assert "plant.params.mass" in msg and "> 0" in msg and "got -1" in msg and "bad.yaml:8:18:" in msg


def test_wrong_type(tmp_path, toy_yaml):
    msg = _error(tmp_path, toy_yaml.read_text().replace("seed: 3", "seed: three"))
    assert "bad.yaml:4:7: seed: expected a whole number, got 'three'" in msg


def test_missing_field(tmp_path, toy_yaml):
    msg = _error(tmp_path, toy_yaml.read_text().replace("paper: none\n", ""))
    assert "missing field 'paper'" in msg


def test_unknown_plugin_lists_known(tmp_path, toy_yaml):
    msg = _error(tmp_path, toy_yaml.read_text().replace("type: toy\n", "type: toyy\n"))
    assert "unknown plant 'toyy'" in msg and "toy" in msg and "plant.type" in msg


def test_rate_must_divide_physics_rate(tmp_path, toy_yaml):
    msg = _error(tmp_path, toy_yaml.read_text().replace("rate: 100,", "rate: 300,"))
    assert "sensors.cam.rate" in msg and "divides" in msg


def test_bad_yaml_syntax(tmp_path):
    msg = _error(tmp_path, "name: [unclosed\n")
    assert "bad.yaml:2" in msg and "not valid YAML" in msg


def test_extends_and_overrides(tmp_path, toy_yaml):
    child = tmp_path / "child.yaml"
    child.write_text("extends: toy.yaml\nname: child\nplant:\n  params: {x0: 0.5}\n")
    sc = load_scenario(child)
    assert sc.name == "child"
    assert sc.plant.params.x0 == 0.5 and sc.plant.params.mass == 2.0   # merged, not replaced
    assert sc.controller.params.target == 1.0


def test_error_in_child_names_child_file(tmp_path, toy_yaml):
    child = tmp_path / "child.yaml"
    child.write_text("extends: toy.yaml\nplant:\n  params: {mass: 0}\n")
    with pytest.raises(ScenarioError) as info:
        load_scenario(child)
    assert "child.yaml:3:" in str(info.value)


def test_extends_missing_file(tmp_path):
    msg = _error(tmp_path, "extends: nowhere.yaml\nname: x\n")
    assert "no such scenario file 'nowhere.yaml'" in msg


def test_set_overrides_and_is_validated(toy_yaml):
    sc = load_scenario(toy_yaml, sets=["plant.params.mass=5", "timing.duration=0.5"], seed=9)
    assert sc.plant.params.mass == 5.0 and sc.timing.duration == 0.5 and sc.seed == 9
    with pytest.raises(ScenarioError) as info:
        load_scenario(toy_yaml, sets=["plant.params.mass=-2"])
    assert "plant.params.mass" in str(info.value) and "--set" in str(info.value)
    with pytest.raises(ScenarioError):
        load_scenario(toy_yaml, sets=["no_equals_sign"])


def test_yaml_is_not_evaluated(tmp_path, toy_yaml):
    msg = _error(tmp_path, toy_yaml.read_text().replace("seed: 3", "seed: !!python/object:os.system 'true'"))
    assert "bad.yaml:4:7:" in msg and "!!python/object:os.system" in msg and "not allowed" in msg


def test_extends_with_another_plugin_type_replaces_its_params(tmp_path, toy_yaml):
    from replay import registry
    import toy_plugins
    registry.register("controller", "toy_pd2", toy_plugins.ToyController)
    child = tmp_path / "child.yaml"
    child.write_text("extends: toy.yaml\ncontroller: {type: toy_pd2, params: {kp: 5}}\n")
    sc = load_scenario(child)
    assert sc.controller.type == "toy_pd2"
    assert sc.controller.params.kp == 5.0
    assert sc.controller.rate == 1000.0       # the base's rate: 500 belonged to the other type
