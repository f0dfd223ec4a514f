"""The arm plant's once-a-step state arithmetic in Python floats (``joint_state``,
``limit_flags``: the PyBullet and MuJoCo arm plants run them)."""

from __future__ import annotations

import math


def joint_state(states: tuple, na: int, pick: tuple, locked: list) -> tuple:
    """((q, qd), (hand q, qd, applied torque)) from getJointStates' tuple ``states`` (the arm's
    ``na`` read joints, then the hand's): per arm joint ``pick`` gives its read joint, or -1
    for a locked joint (q ``locked[i]``, qd 0.0)."""
    pos, vel, _, eff = zip(*states)
    q = [pos[k] if k >= 0 else locked[i] for i, k in enumerate(pick)]
    qd = [vel[k] if k >= 0 else 0.0 for k in pick]
    return (q, qd), (list(pos[na:]), list(vel[na:]), list(eff[na:]))


def limit_flags(q, qd, pos, v, vlim, lower, upper, over0, at0):
    """None when the state is finite and no joint's flags changed since ``over0``, ``at0``;
    else (finite, over, at): over[i] |qd| > vlim, at[i] q <= lower or q >= upper (None, None
    when not finite). ``pos``, ``v``: the object's (None without one)."""
    isfinite = math.isfinite
    finite = all(map(isfinite, q)) and all(map(isfinite, qd))
    if pos is not None:
        finite = finite and all(map(isfinite, pos)) and all(map(isfinite, v))
    if not finite:
        return (False, None, None)
    over = [abs(x) > lim for x, lim in zip(qd, vlim)]
    at = [x <= lo or x >= hi for x, lo, hi in zip(q, lower, upper)]
    if over == over0 and at == at0:
        return None
    return (True, over, at)
