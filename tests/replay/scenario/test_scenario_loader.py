"""The scenario loader: strict types, clear errors with file:line:col and field path, extends, --set."""

import pytest

from replay.scenario import ScenarioError, load_scenario, resolved_yaml, scenario_from_text


def test_loads_and_fills_defaults(toy_yaml):
    sc = load_scenario(toy_yaml)
    assert sc.plant.params.mass == 2.0
    assert sc.plant.params.wall == 10.0  # default filled in
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
    assert (
        "plant.params.mass" in msg and "> 0" in msg and "got -1" in msg and "bad.yaml:8:18:" in msg
    )


def test_out_of_range_names_the_fields_type(tmp_path, toy_yaml):
    # a float field given a whole number is still "a number", an int field "a whole number"
    msg = _error(tmp_path, toy_yaml.read_text().replace("mass: 2.0", "mass: -1"))
    assert "expected a number > 0" in msg and "whole" not in msg
    msg = _error(tmp_path, toy_yaml.read_text().replace("seed: 3", "seed: -3"))
    assert "seed: expected a whole number >= 0" in msg


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
    assert sc.plant.params.x0 == 0.5 and sc.plant.params.mass == 2.0  # merged, not replaced
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
    msg = _error(
        tmp_path, toy_yaml.read_text().replace("seed: 3", "seed: !!python/object:os.system 'true'")
    )
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
    assert sc.controller.rate == 1000.0  # the base's rate: 500 belonged to the other type


# -- the validation layer: every value, every shape, one line at the field's own place ----------


def _set_error(toy_yaml, *sets):
    with pytest.raises(ScenarioError) as info:
        load_scenario(toy_yaml, sets=list(sets))
    text = str(info.value)
    assert "\n" not in text
    return text


@pytest.mark.parametrize(
    "value, expected",
    [
        (".nan", "got NaN"),
        (".inf", "finite"),
        ("-.inf", "finite"),
        ("1" + "0" * 400, "got 1000"),
        ("1.0e300", "<= 1e+09"),
        ("abc", "expected a number"),
    ],
)
def test_numbers_are_finite_and_bounded(toy_yaml, value, expected):
    msg = _set_error(toy_yaml, f"plant.params.x0={value}")
    assert "plant.params.x0" in msg and expected in msg


def test_plain_exponent_is_a_number(toy_yaml):
    assert load_scenario(toy_yaml, sets=["plant.params.mass=3e-2"]).plant.params.mass == 0.03


def test_list_items_are_typed_and_ranged(project_root):
    msg = _set_error("scenarios/stick_3step.yaml", "controller.params.lambda_2=[5, 0]")
    assert "controller.params.lambda_2[0]" in msg and "<= 1" in msg
    msg = _set_error("scenarios/stick_3step.yaml", "controller.params.lambda_2=[0, 0]")
    assert "zero vector" in msg
    msg = _set_error("scenarios/catch_optimised.yaml", "plant.params.base_position=[a, b, c]")
    assert "base_position[0]" in msg and "expected a number" in msg
    msg = _set_error("scenarios/catch_optimised.yaml", "controller.params.throw_speeds=[]")
    assert "throw_speeds" in msg and "1 to 10" in msg


def test_plant_checks_moved_into_params(project_root):
    """Checks the arm plant made in its constructor are the Params' now: validate sees them."""
    msg = _set_error("scenarios/catch_optimised.yaml", "plant.params.initial_q=[0,0]")
    assert "plant.params.initial_q" in msg and "4 values for wam4" in msg
    msg = _set_error("scenarios/catch_optimised.yaml", "plant.params.locked_joints=[J9]")
    assert "locked_joints[0]" in msg
    msg = _set_error("scenarios/catch_optimised.yaml", "plant.params.arm=wam7")
    assert "7 values for wam7" in msg


def test_field_check_points_at_the_field_line(project_root, tmp_path):
    text = (project_root / "scenarios/stick_3step.yaml").read_text()
    line = next(i + 1 for i, l in enumerate(text.splitlines()) if "lambda_2:" in l)
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("lambda_2: [1.0, 0.0]", "lambda_2: [0.0, 0.0]"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(bad)
    assert f"bad.yaml:{line}:" in str(info.value)


def test_rate_error_names_the_rate_line(tmp_path, toy_yaml):
    msg = _error(tmp_path, toy_yaml.read_text().replace("rate: 100,", "rate: 300,"))
    assert "bad.yaml:10:" in msg and "sensors.cam.rate" in msg
    msg = _error(tmp_path, toy_yaml.read_text().replace("rate: 100,", "rate: 1.0e-300,"))
    assert "bad.yaml:10:" in msg and ">= 0.01" in msg


def test_duration_needs_a_step(tmp_path, toy_yaml):
    msg = _error(tmp_path, toy_yaml.read_text().replace("duration: 1.0", "duration: 1.0e-12"))
    assert "bad.yaml:5:" in msg and "timing.duration" in msg and "one physics step" in msg


def test_name_cannot_leave_the_output_folder(toy_yaml):
    msg = _set_error(toy_yaml, "name=../../../x")
    assert "name" in msg and "expected a name" in msg


@pytest.mark.parametrize(
    "data, expected",
    [
        (bytes(range(256)), "not UTF-8"),
        ("name: x\n".encode("utf-16"), "UTF-16"),
        ("# caf\xe9\nname: x\n".encode("latin-1"), "bad.yaml:1:6: not UTF-8"),
        (b"# a\x00b\nname: x\n", "bad.yaml:1:4:"),
        (b"a: " + b"[" * 1000 + b"]" * 1000 + b"\n", "nested deeper"),
        (b"? [a, b]\n: 1\n", "bad.yaml:1:3: a key must be a plain name"),
        (b"a: &a [*a]\n", "recursive alias"),
        (b"<<: {a: 1}\n", "merge keys"),
        (b"- 1\n", "a mapping of fields"),
    ],
)
def test_hostile_yaml_is_one_line(tmp_path, data, expected):
    p = tmp_path / "bad.yaml"
    p.write_bytes(data)
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    assert expected in str(info.value) and "\n" not in str(info.value)


def test_alias_bomb_is_refused_before_it_grows(tmp_path, toy_yaml):
    bomb = "x0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n" + "".join(
        f"x{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]\n" for i in range(1, 9)
    )
    p = tmp_path / "bomb.yaml"
    p.write_text(bomb + toy_yaml.read_text())
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    assert "alias bomb" in str(info.value)


def test_binary_extends_is_one_line(tmp_path):
    (tmp_path / "bin.yaml").write_bytes(bytes(range(256)))
    msg = _error(tmp_path, "extends: bin.yaml\n")
    assert "bin.yaml" in msg and "not UTF-8" in msg


def test_plugin_mismatch_is_one_line_at_controller_type(project_root, tmp_path):
    """The two mismatches of issue 12: both fail in validate, naming controller.type."""
    msg = _set_error(
        "scenarios/stick_3step.yaml", "controller.type=catching", "controller.params={}"
    )
    assert "controller.type" in msg and "ArmSpec" in msg and "AirTableSpec" in msg
    child = tmp_path / "child.yaml"
    child.write_text(
        f"extends: {project_root / 'scenarios/stick_3step.yaml'}\n"
        "plant: {type: arm_rig, params: {}}\n"
    )
    with pytest.raises(ScenarioError) as info:
        load_scenario(child)
    assert "controller.type" in str(info.value) and "AirTableSpec" in str(info.value)
    msg = _set_error("scenarios/catch_optimised.yaml", "sensors={}")
    assert "reads /vision/object" in msg and "no sensor publishes" in msg


def test_inputs_are_recorded(tmp_path, toy_yaml):
    child = tmp_path / "child.yaml"
    child.write_text("extends: toy.yaml\nname: child\n")
    assert load_scenario(child).inputs == (child.resolve(), toy_yaml.resolve())
