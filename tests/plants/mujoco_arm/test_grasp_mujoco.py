"""Issue #24: the grasp in MuJoCo (plants/mujoco_arm/grasp_plant.py). The flat plant type of
older logs steps as the engine field's rig (the scenarios differing from their PyBullet twins only
in that field, the truth topics and fields: test_cross_engine.py, every engine); box and ball are
grasped and held on seeds and human speeds the scenarios do not use (they use seed 0 at
0.10 m/s), judged from the truth topics by the PyBullet robustness test's own criterion
(analysis/grasping/judge.py), >= 90 %; and the contact stiffness chosen (solref) still grasps at
half and twice its value."""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path

import numpy as np
import pytest
import yaml
from grasp_rig import DT, nudged_truth, rig

from analysis.grasping.judge import physical_verdict
from plants.mujoco_arm.grasp_plant import MujocoGraspPlant
from plants.mujoco_arm.params import GraspParams
from plants.mujoco_arm.viewer_scene import MujocoGraspScene
from replay import registry
from replay.messages import to_dict

ROOT = Path(__file__).resolve().parents[3]
# the plug-in in this process too (pyproject's entry point needs `make install`)
registry.register("plant", "mujoco_grasp", MujocoGraspPlant)
registry.register("viewer_scene", "mujoco_grasp", MujocoGraspScene)

# the human paths: seed and speed per object; the suite runs 3 of them (the PyBullet robustness
# test's speeds), MUJOCO_GRASP_PATHS=5 all (docs/mujoco.md: 10/10 in both engines)
PATHS = ((221, 0.05), (223, 0.15), (225, 0.3), (222, 0.10), (224, 0.2))
N_PATHS = int(os.environ.get("MUJOCO_GRASP_PATHS", "3"))
CASES = [
    (scenario, seed, speed)
    for scenario in ("grasp_hexahedron_mujoco", "grasp_sphere_mujoco")
    for seed, speed in PATHS[:N_PATHS]
]


def run(scenario: str, out: Path, sets: list[str]):
    from replay.log import LogReader
    from replay.runner import Runner
    from replay.scenario import load_scenario

    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(ROOT)
        sc = load_scenario(ROOT / "scenarios" / f"{scenario}.yaml", sets=sets)
        log = LogReader(Runner(sc).run(out).path)
    flag = next(e for e in reversed(log.events()) if e["kind"] == "outcome")["data"]
    return physical_verdict(log), flag


def test_the_flat_plant_type_is_the_engine_fields_rig():
    """``mujoco_grasp`` (the plant type of logs before the engine field, MuJoCo's settings flat
    in its params) steps as the grasping rig with ``engine: {type: mujoco}``: equal truth."""
    base = rig(engine={"type": "mujoco"})
    fields = {f.name: getattr(base.params, f.name) for f in dataclasses.fields(base.params)}
    fields.pop("engine")
    flat = MujocoGraspPlant(GraspParams(**fields), dt=DT, rng=np.random.default_rng(0))
    ta, tb = nudged_truth(base), nudged_truth(flat)
    assert ta.keys() == tb.keys()
    for topic in ta:
        assert to_dict(ta[topic]) == to_dict(tb[topic]), topic


@pytest.fixture(scope="module")
def verdicts(tmp_path_factory):
    out = tmp_path_factory.mktemp("grasp_mujoco")
    return {
        (scenario, seed, speed): run(
            scenario,
            out / f"{scenario}-{seed}.mcap",
            [f"seed={seed}", f"plant.params.human_speed={speed}"],
        )
        for scenario, seed, speed in CASES
    }


def test_no_mujoco_run_logs_success_that_the_physics_rejects(verdicts):
    for case, ((ok, why), flag) in verdicts.items():
        print(case, ok, why, "| flag:", flag["success"], flag["reason"])
        assert ok or not flag["success"], (case, why, flag["reason"])


def test_mujoco_grasps_and_holds_on_unseen_seeds_and_speeds(verdicts):
    good = sum(ok for (ok, _), _ in verdicts.values())
    assert good >= math.ceil(0.9 * len(verdicts)), {
        c: why for c, ((ok, why), _) in verdicts.items()
    }


@pytest.mark.parametrize("stiffness", [0.5, 2.0])
def test_contact_stiffness_neighbours_still_grasp(tmp_path, stiffness):
    """solref's stiffness k = 1 / (tc z)^2 at half and twice the chosen (the damping ratio z
    kept): tc x sqrt(2), x 1 / sqrt(2)."""
    tc, z = yaml.safe_load((ROOT / "scenarios" / "grasp_hexahedron_mujoco.yaml").read_text())[
        "plant"
    ]["params"]["engine"]["mj_solref"]
    tc = max(tc / math.sqrt(stiffness), 0.002)
    (ok, why), flag = run(
        "grasp_hexahedron_mujoco",
        tmp_path / "n.mcap",
        [f"plant.params.engine.mj_solref=[{tc:.6f}, {z}]", "seed=226"],
    )
    print(stiffness, tc, ok, why)
    assert ok and flag["success"], (why, flag["reason"])


def test_every_grasp_row_shows_both_engines(tmp_path):
    """analysis/engines.py joins the grasp claims (analysis.grasping.claims) of both engines' runs
    of the same scenarios, each decided on its own engine's truth; the hold holds in both."""
    from analysis.engines import closing_note, engine_rows, split_logs
    from analysis.grasping.claims import STABLE, evaluate
    from replay.log import LogReader
    from replay.runner import Runner
    from replay.scenario import load_scenario

    logs = {}
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(ROOT)
        for name in ("grasp_hexahedron", "grasp_sphere"):
            for n in (name, name + "_mujoco"):
                Runner(load_scenario(ROOT / "scenarios" / f"{n}.yaml")).run(tmp_path / f"{n}.mcap")
                logs[n] = LogReader(str(tmp_path / f"{n}.mcap"))
    groups = split_logs(logs)
    pb, mj = groups["PyBullet"], groups["MuJoCo"]
    assert set(pb) == set(mj) == {"grasp_hexahedron", "grasp_sphere"}
    rows = engine_rows(evaluate, logs)
    assert {r.quantity for r in rows} == {r.quantity for r in evaluate(pb)}
    for r in rows:
        assert r.measured.startswith("PyBullet: ") and " ‖ MuJoCo: " in r.measured, r.quantity
    # one row for the claim over both objects (one row per finding, analysis/claims.py)
    held = [r for r in rows if r.quantity == STABLE]
    assert len(held) == 1 and all(r.status == "reproduced" for r in held), held
    both = closing_note(rows).splitlines()[0]
    assert all(r.quantity in both for r in held)
