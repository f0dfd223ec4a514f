"""The mujoco_arm plug-ins registered in this process: the shared venv's editable install sees a
new ``paper_replay.plants`` entry point only once reinstalled (pyproject.toml declares them)."""

import pytest


@pytest.fixture(autouse=True, scope="session")
def _mujoco_plugins():
    from plants.mujoco_arm.plant import MujocoArmPlant
    from plants.mujoco_arm.viewer_scene import MujocoArmScene
    from replay import registry

    registry.register("plant", "mujoco_arm", MujocoArmPlant)
    registry.register("viewer_scene", "mujoco_arm", MujocoArmScene)
