"""The grasp's physical criterion from the truth topics alone (issue #20), shared by the PyBullet
and MuJoCo robustness tests (tests/analysis/test_grasp_robustness.py,
tests/plants/mujoco_arm/test_grasp_mujoco.py) and the stored per-engine rates
(analysis/engine_rates.py), never by the run's outcome flag:

- grasped: the plant's grasp event (contacts) and the object held for >= 0.5 s after it;
- held: during that hold the object stays within 10 mm of where it sat in the true hand frame;
- with the human: within 20 mm of the human's path while held;
- on its plane: within 20 mm of the constraint plane over the whole run.
"""

from __future__ import annotations

import numpy as np


def physical_verdict(log) -> tuple[bool, str]:
    from analysis.grasping.run import load_run

    run = load_run(log)
    grasps = run.kinds("grasp")
    if not grasps:
        return False, "never grasped"
    t0 = grasps[0]["t"]
    held_until = next((e["t"] for e in run.kinds("release") if e["t"] > t0), run.t_end)
    if held_until - t0 < 0.5 - 1e-9:
        return False, f"held {held_until - t0:.3f} s"
    w = run.window(run.t_obj, t0, held_until)
    rel = run.in_hand()[w]
    drift = float(np.max(np.linalg.norm(rel - rel[0], axis=1)))
    target = np.column_stack(
        [np.interp(run.t_obj[w], run.t_human, run.human[:, i]) for i in range(3)]
    )
    human = float(np.max(np.linalg.norm(run.obj[w] - target, axis=1)))
    plane_x = float(run.plant_params["object_position"][0])  # the plane's normal is world x
    off = float(np.max(np.abs(run.obj[:, 0] - plane_x)))
    why = []
    if drift > 0.010:
        why.append(f"moved {1e3 * drift:.1f} mm in the hand")
    if human > 0.020:
        why.append(f"{1e3 * human:.1f} mm off the human's path")
    if off > 0.020:
        why.append(f"{1e3 * off:.1f} mm off its plane")
    return not why, "; ".join(why) or (
        f"held {held_until - t0:.2f} s, {1e3 * drift:.1f} mm in the hand, "
        f"{1e3 * human:.1f} mm from the human, {1e3 * off:.1f} mm off the plane"
    )
