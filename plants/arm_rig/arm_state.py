"""The arm plant's once-a-step state arithmetic in Python floats (``joint_state``,
``limit_flags``, ``limit_torque`` and ``torque_limit_events``, the rig's ``_limit_torque``
step): the arm rig (rig.py) and its PyBullet plant run them."""

from __future__ import annotations

import math

from replay.interfaces import Occurrence


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


def limit_torque(cmd: list, tlim: list, locked: list, enforce: bool, vlim: list, qd: list):
    """(applied, clamped) per joint: the commanded torque clipped to the limits ``tlim``
    (non-finite: 0, clamped), zero on a ``locked`` joint and, with ``enforce``, zero where it
    would push a joint at its speed limit ``vlim`` further (clamped). The usual case (no speed
    limit enforced, every command finite) in one pass over the joints; else joint by joint
    (:func:`limit_torque_loop`, the same results)."""
    if enforce or not math.isfinite(sum(cmd)):
        return limit_torque_loop(cmd, tlim, locked, enforce, vlim, qd)
    applied = [min(max(x, -lim), lim) for x, lim in zip(cmd, tlim)]
    clamped = [a != x for a, x in zip(applied, cmd)]
    if True in locked:
        for i, lk in enumerate(locked):
            if lk:
                applied[i], clamped[i] = 0.0, False
    return applied, clamped


def limit_torque_loop(cmd: list, tlim: list, locked: list, enforce: bool, vlim: list, qd: list):
    """:func:`limit_torque` joint by joint in plain Python (4-7 floats)."""
    n = len(cmd)
    applied, clamped = [0.0] * n, [False] * n
    for i, (x, lim) in enumerate(zip(cmd, tlim)):
        if locked[i]:
            continue
        if not math.isfinite(x):
            clamped[i] = True  # a non-finite command gives no torque
            continue
        a = min(max(x, -lim), lim)
        c = a != x
        v = qd[i]
        if enforce and abs(v) >= vlim[i] and a != 0.0 and (a > 0.0) == (v > 0.0):  # same sign
            a, c = 0.0, True
        applied[i], clamped[i] = a, c
    return applied, clamped


def torque_limit_events(clamped, episode, cmd, applied, names, tlim) -> list[Occurrence]:
    """A ``torque_limit`` event per joint clamped now and not in the step before (``episode``);
    ``cmd`` None: torques no command gave (velocity servos' own), no ``commanded`` field."""
    events = []
    for i, c in enumerate(clamped):
        if c and not episode[i]:
            data: dict = {"joint": names[i]}
            if cmd is not None:
                data["commanded"] = cmd[i] if math.isfinite(cmd[i]) else None
            data["applied"], data["limit"] = applied[i], tlim[i]
            events.append(Occurrence("torque_limit", data))
    return events
