"""The catch in Drake on throws it was not tuned to: tests/analysis/test_catch_robustness.py's
seeded throws (8-10 m/s at first sight, tilted by up to 1 deg, r_o(t0) jittered by 5 mm; the same
generator and seed, ``CATCH_THROWS`` of them), the whole pipeline, judged by the plant's verdict
and by the truth topics alone (the ball still in the hand frame, /object/state and
/effector/motion). The Drake contact settings' neighbours (x0.5, x2) run on the first
``DRAKE_NEIGHBOUR_THROWS`` (default 4; docs/drake.md gives the table for 30): the chosen values
must not decide the catch by themselves. Run with ``-s`` to see the rates."""

from __future__ import annotations

import os

import numpy as np
import pytest
from arm_checks import robust
from arm_checks import run_throws as _run_throws

N_NEIGHBOUR_THROWS = int(os.environ.get("DRAKE_NEIGHBOUR_THROWS", "4"))
NEIGHBOURS = {
    "stiffness x0.5": {"dk_point_stiffness": "5.0e4"},
    "stiffness x2": {"dk_point_stiffness": "2.0e5"},
    "dissipation x0.5": {"dk_dissipation": "5.0"},
    "dissipation x2": {"dk_dissipation": "20.0"},
    "servo gain x0.5": {"dk_hand_servo_gain": "50.0"},
    "servo gain x2": {"dk_hand_servo_gain": "200.0"},
}


def held_in_hand(log, hold: float = 0.05) -> bool:
    """Truth only: over the run's last ``hold`` s the ball's centre in the tool frame moved
    < 5 mm and stayed within 0.1 m of the tool, and the run stopped (at the catch) before its
    0.45 s."""
    obj, eff = log.series("/object/state"), log.series("/effector/motion")
    n = min(len(obj), len(eff))
    t_end = obj[n - 1]["t"]
    rel = []
    for o, e in zip(obj[:n], eff[:n]):
        if o["t"] >= t_end - hold - 1e-9:
            x, y, z, w = e["orientation"]
            R = np.array(
                [
                    [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                    [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                    [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
                ]
            )
            rel.append(R.T @ (np.asarray(o["position"]) - e["position"]))
    a = np.array(rel)
    drift = np.linalg.norm(a - a[0], axis=1).max()
    return bool(drift < 0.005 and np.linalg.norm(a, axis=1).max() < 0.1 and t_end < 0.449)


def run_throws(name: str, throws: list, out, sets: dict | None = None) -> list[tuple]:
    """(the plant's outcome, the truth's verdict) of scenario ``name`` on each throw, ``sets``
    Drake's settings (plant.params.engine.*)."""
    from replay.log import LogReader

    engine = {f"engine.{k}": v for k, v in (sets or {}).items()}
    return [(o, held_in_hand(LogReader(p))) for o, p in _run_throws(name, throws, out, engine)]


def rate(res: list[tuple]) -> float:
    return sum(truth for _, truth in res) / len(res)


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    throws = robust._throws(robust.N_THROWS)
    res = run_throws("catch_optimised_drake", throws, tmp_path_factory.mktemp("drake"))
    fails = sorted({o["reason"] for o, ok in res if not ok})
    print(f"\nDrake catch rate over {len(throws)} seeded throws: {100 * rate(res):.1f} % {fails}")
    return res


def test_drake_catches_the_perturbed_throws(outcomes):
    assert rate(outcomes) >= 0.9, [o["reason"] for o, ok in outcomes if not ok]


def test_the_plants_verdict_is_the_truths(outcomes):
    """The plant's catch verdict (from Drake's contacts) agrees with the truth topics' run by
    run, and says why in the rig's vocabulary (plants/arm_rig/outcome.py)."""
    for o, truth in outcomes:
        assert o["success"] == truth, o
        assert isinstance(o["success"], bool) and o["reason"]
        if o["success"]:
            assert o["reason"] == "caught" and o["catch_time"] > o["first_contact_time"]


def test_contact_settings_do_not_decide_the_catch(tmp_path):
    """Each neighbour (x0.5, x2) of the chosen contact and servo settings catches too."""
    throws = robust._throws(robust.N_THROWS)[:N_NEIGHBOUR_THROWS]
    rates = {}
    for label, sets in NEIGHBOURS.items():
        rates[label] = rate(run_throws("catch_optimised_drake", throws, tmp_path, sets))
        print(f"  {label:20s} {100 * rates[label]:5.1f} %")
    assert min(rates.values()) >= 0.9, rates
