"""The grasp in Drake (plants/drake_arm/grasp_plant.py's adapter) on seeds and human speeds the scenarios do
not use (they use seed 0 at 0.10 m/s), judged from the truth topics by the PyBullet robustness
test's own criterion (analysis/grasping/judge.py): the ball is held >= 90 %; the box is held at the
slower human speeds, and where not (docs/drake.md: 20/23 on analysis/engine_rates.py's paths, all
three failures at 0.3 m/s) the box slides along the hand while the human pulls with ~3 N against
a grip of > 100 N, a contact-model difference measured there, not a method's. The contact stiffness chosen still
grasps at half and twice. (The truth topics and fields: test_cross_engine.py, every engine.)"""

from __future__ import annotations

import math
import os
from pathlib import Path

import pytest
import yaml

from analysis.grasping.judge import physical_verdict

ROOT = Path(__file__).resolve().parents[3]
# test_grasp_mujoco.py's paths; the suite runs 3, DRAKE_GRASP_PATHS=5 all
PATHS = ((221, 0.05), (223, 0.15), (225, 0.3), (222, 0.10), (224, 0.2))
N_PATHS = int(os.environ.get("DRAKE_GRASP_PATHS", "3"))
CASES = [
    (scenario, seed, speed)
    for scenario in ("grasp_hexahedron_drake", "grasp_sphere_drake")
    for seed, speed in PATHS[:N_PATHS]
]


def run(scenario: str, out: Path, sets: list[str]):
    from replay.log import LogReader
    from replay.runner import Runner
    from replay.scenario import load_scenario

    sc = load_scenario(ROOT / "scenarios" / f"{scenario}.yaml", sets=sets)
    log = LogReader(Runner(sc).run(out).path)
    flag = next(e for e in reversed(log.events()) if e["kind"] == "outcome")["data"]
    return physical_verdict(log), flag


@pytest.fixture(scope="module")
def verdicts(tmp_path_factory):
    out = tmp_path_factory.mktemp("grasp_drake")
    return {
        (scenario, seed, speed): run(
            scenario,
            out / f"{scenario}-{seed}.mcap",
            [f"seed={seed}", f"plant.params.human_speed={speed}"],
        )
        for scenario, seed, speed in CASES
    }


def test_a_flagged_grasp_the_physics_rejects_is_a_regrasp(verdicts):
    """The rig's flag and the physical criterion agree, except where the first grasp was
    released before 0.5 s and a later one held (the criterion judges the first grasp only:
    seed 225 at 0.3 m/s, the box, in Drake)."""
    for case, ((ok, why), flag) in verdicts.items():
        print(case, ok, why, "| flag:", flag["success"], flag["reason"])
        assert ok or not flag["success"] or why.startswith("held 0."), (case, why, flag)


def test_drake_grasps_and_holds_on_unseen_seeds_and_speeds(verdicts):
    by = {
        name: [ok for (s, _, _), ((ok, _), _) in verdicts.items() if s == name]
        for name in ("grasp_sphere_drake", "grasp_hexahedron_drake")
    }
    why = {c: w for c, ((ok, w), _) in verdicts.items() if not ok}
    assert sum(by["grasp_sphere_drake"]) >= math.ceil(0.9 * len(by["grasp_sphere_drake"])), why
    # the box: every path below 0.3 m/s held (the measured limit above)
    assert all(ok for (s, _, v), ((ok, _), _) in verdicts.items() if v < 0.3), why


@pytest.mark.parametrize("stiffness", [0.5, 2.0])
def test_contact_stiffness_neighbours_still_grasp(tmp_path, stiffness):
    """The point contact stiffness at half and twice the scenario's, on an unseen seed."""
    k = yaml.safe_load((ROOT / "scenarios" / "grasp_hexahedron_drake.yaml").read_text())["plant"][
        "params"
    ]["engine"]["dk_point_stiffness"]
    (ok, why), flag = run(
        "grasp_hexahedron_drake",
        tmp_path / "n.mcap",
        [f"plant.params.engine.dk_point_stiffness={k * stiffness:.1f}", "seed=226"],
    )
    print(stiffness, ok, why)
    assert ok and flag["success"], (why, flag["reason"])
