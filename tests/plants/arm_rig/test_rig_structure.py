"""The arm rig is written once and engine-free (issue #39): its modules import no physics engine,
and each engine's plant takes the rig's spec, truth, events, limit checks and step order rather
than a copy of its own."""

from __future__ import annotations

import pkgutil
import re
import subprocess
import sys

import plants.arm_rig

RIG_METHODS = ("_make_spec", "_check_events", "_limit_events", "_limit_torque")


def test_no_arm_rig_module_imports_an_engine():
    names = [f"plants.arm_rig.{m.name}" for m in pkgutil.iter_modules(plants.arm_rig.__path__)]
    assert "plants.arm_rig.rig" in names and "plants.arm_rig.grasp_rig" in names
    code = (
        "import importlib, sys\n"
        f"for n in {names!r}: importlib.import_module(n)\n"
        "print(sorted(m for m in ('pybullet', 'mujoco') if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_plant_types_are_the_rigs_and_old_types_run_the_rigs_own_methods():
    """``arm_rig`` and ``grasp_rig`` are the engine-free rigs themselves (the engine from the
    field); an old log's ``mujoco_arm``/``mujoco_grasp`` is the rig with a fixed adapter."""
    from plants.arm_rig.grasp_rig import GraspRig
    from plants.arm_rig.rig import ArmRig
    from plants.mujoco_arm.grasp_plant import MujocoGraspPlant
    from plants.mujoco_arm.plant import MujocoArmPlant
    from replay import registry

    assert registry.load("plant", "arm_rig") is ArmRig and ArmRig.Engine is None
    assert registry.load("plant", "grasp_rig") is GraspRig and GraspRig.Engine is None
    assert registry.load("plant", "bullet_arm") is ArmRig  # (an old log's name, renamed)
    assert MujocoArmPlant.__bases__ == (ArmRig,) and GraspRig.__bases__ == (ArmRig,)
    for name in RIG_METHODS + ("truth", "scene", "outcome", "step", "apply"):
        assert getattr(MujocoArmPlant, name) is getattr(ArmRig, name), name
    assert MujocoGraspPlant.__bases__ == (GraspRig,), MujocoGraspPlant.__mro__  # no mixin
    for cls in (GraspRig, MujocoGraspPlant):
        for name in RIG_METHODS + ("_torque_events",):
            assert getattr(cls, name) is getattr(ArmRig, name), (cls.__name__, name)
        # the grasp rig's own truth, scene, command, verdict: one of each for every engine
        for name in ("truth", "scene", "joints", "frames", "apply", "step", "outcome"):
            assert getattr(cls, name) is vars(GraspRig)[name], (cls.__name__, name)


def test_no_arm_rig_class_reads_another_objects_private_state():
    """The rig's parts (verdict, topics, servos, head, human, set-up) are fed readings or read
    public attributes: no ``x._name`` in plants/arm_rig but on ``self``."""
    from pathlib import Path

    pattern = re.compile(r"\b(?!self\b)[A-Za-z_][A-Za-z0-9_]*\)?\._[a-z]")
    found = [
        f"{path.name}:{i}: {line.strip()}"
        for path in sorted(Path(plants.arm_rig.__path__[0]).glob("*.py"))
        for i, line in enumerate(path.read_text().splitlines(), 1)
        if pattern.search(line)
    ]
    assert found == []


def test_engine_plants_only_name_their_adapter():
    """An engine's plant is the rig plus its adapter class (plants/arm_rig/engine.py): it defines
    no method of its own, and its adapter defines every method of the adapter protocol."""
    from plants.arm_rig.engine import EngineAdapter
    from plants.arm_rig.grasp_rig import GraspEngine
    from plants.mujoco_arm.grasp_plant import MujocoGraspPlant
    from plants.mujoco_arm.plant import MujocoArmPlant

    def methods(protocol) -> set[str]:
        return {n for n, v in vars(protocol).items() if callable(v) and not n.startswith("_")}

    arm, grasp = methods(EngineAdapter), methods(GraspEngine)
    assert {"state", "advance", "object_contacts", "frames"} <= arm
    for cls in (MujocoArmPlant, MujocoGraspPlant):  # (old logs' types)
        own = {n for n in vars(cls) if not n.startswith("_")}
        assert own == {"Params", "Engine", "description"}, (cls.__name__, own)
        want = arm | (grasp if cls is MujocoGraspPlant else set())
        missing = [n for n in want if not callable(getattr(cls.Engine, n, None))]
        assert not missing, (cls.Engine.__name__, missing)
    from plants.arm_rig.engine import adapter_class, engines

    for name, entry in engines().items():  # every registered engine's adapters
        for role, want in (("arm", arm), ("grasp", arm | grasp)):
            adapter = adapter_class(entry.load(), role)
            missing = [n for n in want if not callable(getattr(adapter, n, None))]
            assert not missing, (name, role, missing)
