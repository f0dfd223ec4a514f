"""The catch family's parameters refuse what no arm can do, with a one-line reason, and the direct
mapping's ``after_catch: track`` holds where its Jacobian cannot be inverted."""

from __future__ import annotations

import pytest

from replay.api import run
from replay.control.catching.model import active_joints
from replay.scenario.yamlio import ScenarioError


@pytest.mark.parametrize("scenario", ["predictive_catch", "catch_feedback"])
@pytest.mark.parametrize(
    "setting, words",
    [
        ("controller.params.held_joints=[J9]", "expected one of J1"),
        ("controller.params.selected_joint=J0", "expected one of J1"),
        ("controller.params.kp=[1e30, 1, 1, 1]", "<= 1e+06"),
        ("controller.params.kd=[1, 1, 1, 1, 1, 1, 1, 1]", "7"),
    ],
)
def test_baselines_bound_their_joints_and_gains(scenario, setting, words):
    with pytest.raises(ScenarioError, match=words.replace("+", r"\+")):
        run(scenario, set=[setting, "timing.duration=0.01"])


def test_a_joint_the_arm_lacks_is_named():
    with pytest.raises(ValueError, match=r"the arm has no joint J6 \(its joints: J1, J2, J3, J4\)"):
        active_joints(("J1", "J2", "J3", "J4"), ["J6"], "J4", "the predictive baseline")
    assert active_joints(("J1", "J2", "J3", "J4"), ["J3"], "J4", "x") == (0, 1, 3)


def test_tracking_past_the_catch_surface_holds_where_the_mapping_is_singular():
    r = run("catch_initial", set=["controller.params.after_catch=track"])
    kinds = [e["kind"] for e in r.events]
    assert r.status == "complete", r.problems
    # the ball reaches the origin of l_c^-1: the run goes on, holding, said once
    assert kinds.count("mapping_singular") == 1
    assert "mapping_hold" not in kinds
