"""The Barrett WAM as a :class:`SerialChain`, from the parameter table ``data/robots/wam.yaml``.

Table sources (see the YAML): WAM User's Manual D1001 (2008) standard DH table and joint limits;
libbarrett ``config/wam4.conf`` / ``wam7w.conf`` ("From inertial specifications Sept 2008") for
masses, centres of mass and inertia tensors, each in DH frame i, about the centre of mass.

- 4-DOF: axes J1..J4, then the tool plate (alpha 0, a 0, d = ``tool_4dof_d``; the manual says
  0.35 m, libbarrett's wam4.conf 0.36 m) and link 4 = ``L4_wam4``.
- 7-DOF: axes J1..J7 with links L1, L2, L3, ``L4_wam7``, L5, L6, L7; the tool frame is DH
  frame 7 (the wrist's output flange) unless ``tool_d`` is given.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
import yaml

from replay.resources import data_path
from replay.robot.serial_chain import DHRow, RigidBody, SerialChain
from replay.spatial import rpy_to_matrix, transform

WAM_YAML = data_path("robots", "wam.yaml")

# Joint torque limits (N*m). Sources disagree (wam.yaml, torque_limits_notes):
#  - "libbarrett": the control-signal limits of libbarrett's joint controllers (wam4.conf:
#    control_signal_limit = (25, 20, 15, 15); wrist 5 N*m);
#  - "public_urdf": the effort limits of a public WAM URDF model (60, 60, 45, 30, 10, 10, 10).
TORQUE_LIMIT_SETS: dict[str, tuple[float, ...]] = {
    "libbarrett": (25.0, 20.0, 15.0, 15.0, 5.0, 5.0, 5.0),
    "public_urdf": (60.0, 60.0, 45.0, 30.0, 10.0, 10.0, 10.0),
}

# Joint speed limit (rad/s) used when a scenario gives none. wam.yaml has no joint speeds and the
# stock WAM's are not in our sources: 3.0 rad/s per axis is an assumption of the order of a stock
# WAM (a ~1 m arm at ~3 m/s), not fitted to the catching paper's 5 m/s.
DEFAULT_VELOCITY_LIMIT = 3.0


@lru_cache(maxsize=8)
def _load(path: str) -> dict:
    with open(path, encoding="utf-8") as f:
        return yaml.safe_load(f)


def load_wam_table(path: str | Path | None = None) -> dict:
    """The parsed parameter table (a fresh copy)."""
    import copy

    return copy.deepcopy(_load(str(path or WAM_YAML)))


def _link_keys(dof: int) -> list[str]:
    if dof == 4:
        return ["L1", "L2", "L3", "L4_wam4"]
    if dof == 7:
        return ["L1", "L2", "L3", "L4_wam7", "L5", "L6", "L7"]
    raise ValueError(f"a WAM has 4 or 7 axes, not {dof}")


def wam_dh(dof: int = 4, table: dict | None = None) -> list[DHRow]:
    t = table or load_wam_table()
    _link_keys(dof)
    return [DHRow(float(r["alpha"]), float(r["a"]), float(r["d"])) for r in t["dh"][:dof]]


def wam_links(dof: int = 4, table: dict | None = None) -> list[RigidBody]:
    t = table or load_wam_table()
    return [
        RigidBody(float(t["links"][k]["mass"]), t["links"][k]["com"], t["links"][k]["inertia"])
        for k in _link_keys(dof)
    ]


def wam_joint_names(dof: int = 4, table: dict | None = None) -> tuple[str, ...]:
    t = table or load_wam_table()
    return tuple(r["joint"] for r in t["dh"][:dof])


def wam_joint_limits(dof: int = 4, table: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) joint limits in rad, from the manual."""
    t = table or load_wam_table()
    names = wam_joint_names(dof, t)
    lim = np.array([t["joint_limits"][n] for n in names], dtype=float)
    return lim[:, 0], lim[:, 1]


def wam_torque_limits(dof: int = 4, source: str = "public_urdf") -> np.ndarray:
    return np.array(TORQUE_LIMIT_SETS[source][:dof], dtype=float)


def default_tool_d(dof: int, table: dict | None = None) -> float:
    t = table or load_wam_table()
    return float(t["tool_4dof_d"]) if dof == 4 else 0.0


def base_transform(
    position=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0), table: dict | None = None
) -> np.ndarray:
    """World pose of DH frame 0: the base plate's pose, then ``base_height`` up to J1/J2's axes."""
    t = table or load_wam_table()
    plate = transform(rpy_to_matrix(rpy), position)
    return plate @ transform(translation=(0.0, 0.0, float(t["base_height"])))


def wam_chain(
    dof: int = 4,
    *,
    tool_d: float | None = None,
    base_position=(0.0, 0.0, 0.0),
    base_rpy=(0.0, 0.0, 0.0),
    gravity: float = 9.81,
    payload: RigidBody | None = None,
    table: dict | None = None,
) -> SerialChain:
    """The WAM model. ``payload`` (mass properties in the tool frame, e.g. a hand) is added to the
    last link; ``gravity`` is the magnitude of g along world -z (m/s^2)."""
    t = table or load_wam_table()
    d = default_tool_d(dof, t) if tool_d is None else float(tool_d)
    chain = SerialChain(
        wam_dh(dof, t),
        wam_links(dof, t),
        base=base_transform(base_position, base_rpy, t),
        tool=transform(translation=(0.0, 0.0, d)),
        gravity=(0.0, 0.0, -float(gravity)),
        joint_names=wam_joint_names(dof, t),
    )
    return chain.with_payload(payload) if payload is not None else chain
