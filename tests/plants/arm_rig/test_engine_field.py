"""``plant.params.engine``: a scenario's physics engine and its settings, refused in one line
when the type is missing or unknown, or a setting is not the engine's."""

from __future__ import annotations

from pathlib import Path

import pytest

from replay.api import run
from replay.scenario.yamlio import ScenarioError

ROOT = Path(__file__).resolve().parents[3]


@pytest.mark.parametrize(
    "setting, words",
    [
        ("plant.params.engine.mj_solref=[0.002, 1.0]", "settings without a type: add type: ENGINE"),
        ("plant.params.engine.type=bogus", "unknown engine type 'bogus' (known: "),
        ("plant.params.engine={type: mujoco, dk_nope: 1}", "dk_nope"),
        ("plant.params.engine=3", "expected a mapping, got '3'"),
    ],
)
def test_a_bad_engine_field_is_one_line(setting, words):
    with pytest.raises(ScenarioError, match=r"plant\.params\.engine") as info:
        run("catch_optimised", set=[setting, "timing.duration=0.01"])
    assert words in str(info.value) and "\n" not in str(info.value)


def test_the_field_chooses_the_engine_of_the_same_scenario():
    r = run("catch_optimised", set=["plant.params.engine.type=mujoco", "timing.duration=0.05"])
    assert r.scenario["plant"]["params"]["engine"]["type"] == "mujoco"
    assert r.table("/object/state")["t"].size > 0


def test_setting_another_engine_drops_the_old_engines_settings():
    """``--set plant.params.engine.type=mujoco`` on a Drake scenario: the dk_ settings belong
    to Drake (as ``extends:`` replaces the engine whole when its type changes), the new engine
    starts from its defaults and takes any setting given with it, in either order."""
    from replay.scenario import load_scenario

    drake = ROOT / "scenarios" / "catch_optimised_drake.yaml"
    mujoco = ["plant.params.engine.type=mujoco"]
    sc = load_scenario(drake, sets=mujoco)
    plain = load_scenario(ROOT / "scenarios" / "catch_optimised.yaml", sets=mujoco)
    assert sc.plant.params.engine == plain.plant.params.engine  # MuJoCo's defaults
    for sets in (
        ["plant.params.engine.mj_iterations=10", *mujoco],
        [*mujoco, "plant.params.engine.mj_iterations=10"],
    ):
        assert load_scenario(drake, sets=sets).plant.params.engine["mj_iterations"] == 10
    same = load_scenario(drake, sets=["plant.params.engine.type=drake"])
    assert same.plant.params.engine == load_scenario(drake).plant.params.engine
