"""MuJoCo's settings (plants/mujoco_arm/params.py): each value they accept is one MuJoCo runs."""

from __future__ import annotations

import dataclasses


def test_every_integrator_the_settings_offer_runs():
    """mj_integrator's choices (what `replay validate` accepts) each map to MuJoCo's: RK4 was
    offered and ended a run with "plant: refused the scenario: KeyError: 'RK4'"."""
    from plants.mujoco_arm.params import MujocoSettings
    from plants.mujoco_arm.world import INTEGRATORS
    from replay.api import run

    field = next(f for f in dataclasses.fields(MujocoSettings) if f.name == "mj_integrator")
    assert set(field.metadata["choices"]) == set(INTEGRATORS)
    engine = ["plant.params.engine.type=mujoco", "plant.params.engine.mj_integrator=RK4"]
    r = run("grasp_sphere", set=[*engine, "timing.duration=0.02"])
    assert r.scenario["plant"]["params"]["engine"]["mj_integrator"] == "RK4"
