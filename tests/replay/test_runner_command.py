"""``Runner.step(command)``: a command given from outside for a step, the rest of the run alike."""

from __future__ import annotations

import pytest

from replay.golden import compare_logs
from replay.runner import Runner
from replay.scenario import load_scenario

EXACT = {"abs": 0, "rel": 0}


def _drive(sc, out, outside: bool):
    """The run stepped by hand: the controller's own command passed in (``outside``), or asked
    by the runner (``step()``)."""
    r = Runner(sc)
    r.start(out)
    given = 0
    while not r.done:
        delivered = r.sense()
        if outside and r.k % r.ctrl_div == 0:
            r.step(r.controller.update(r.k / r.rate, delivered))
            given += 1
        else:
            r.step()
    return r.finish(), given


@pytest.mark.parametrize("name", ["stick_3step", "catch_optimised"])
def test_command_from_outside_gives_the_same_log(name, tmp_path):
    sc = load_scenario(name, ["timing.duration=0.3"], seed=3)
    whole = Runner(sc).run(tmp_path / "run.mcap")
    by_hand, given = _drive(
        load_scenario(name, ["timing.duration=0.3"], seed=3), tmp_path / "hand.mcap", True
    )
    assert given > 0
    assert by_hand.outcome == whole.outcome
    assert by_hand.steps == whole.steps
    assert compare_logs(whole.path, by_hand.path, {}, EXACT) == []


def test_an_outside_command_reaches_the_plant(tmp_path):
    """Not the controller's: the hand's base goes where the command says."""
    from replay.api import open_log
    from replay.robot.hand2d import HandCommand

    sc = load_scenario("stick_3step", ["timing.duration=0.3"], seed=0)
    r = Runner(sc)
    r.start(tmp_path / "out.mcap")
    spec = r.plant.spec()
    target = (0.15, -0.1)
    while not r.done:
        r.step(HandCommand(target, spec.hand.start_joints))
    hand = open_log(r.finish().path).table("/hand/state")
    assert hand["base_target"][-1] == pytest.approx(target, abs=1e-12)
    assert hand["base"][-1] == pytest.approx(target, abs=1e-6)  # 1 m/s: there in 0.18 s
