"""`make bench`'s measuring parts: the bare engine is the engine, and a run times its own parts."""

import pytest

from replay.bench import bare_stepper, engine_in_run
from replay.runner import COMPONENTS, Runner
from replay.scenario import load_scenario


@pytest.mark.parametrize(
    "path,engine",
    [("scenarios/stick_3step.yaml", "pymunk"), ("scenarios/catch_optimised.yaml", "pybullet")],
)
def test_the_bare_stepper_steps_the_engine_not_the_plant(path, engine):
    sc = load_scenario(path)
    name, plant, step = bare_stepper(Runner(sc))
    assert name.startswith(engine)
    before = plant.scene().primitives[0].position
    for _ in range(20):
        step()
    getattr(plant, "invalidate_state", lambda: None)()  # stepped behind its back
    assert plant.scene().primitives[0].position != before  # the engine moved the body
    assert plant._steps == 0  # the plant's step never ran
    plant.close()


def test_a_run_times_its_parts_and_the_engine_inside_it(tmp_path):
    sc = load_scenario("scenarios/stick_3step.yaml", sets=["timing.duration=0.05"])
    result = Runner(sc).run(tmp_path / "run.mcap")
    assert tuple(result.timings) == COMPONENTS
    assert all(v >= 0.0 for v in result.timings.values())
    assert sum(result.timings.values()) == pytest.approx(result.wall_time, rel=1e-9)
    assert result.timings["sensors"] > 0.0 and result.timings["logging"] > 0.0
    run_cpu, engine_cpu, steps = engine_in_run(sc, tmp_path / "engine.mcap")
    assert steps == result.steps
    assert 0.0 < engine_cpu < run_cpu
