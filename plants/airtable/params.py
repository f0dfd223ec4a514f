"""Parameters of the air-table plant (Higashimori et al. 2007, Sec. IV-A), SI units.

The YAML under ``plant.params`` mirrors these dataclasses field for field, e.g.::

    params:
      stick: {collision_width: 0.010}
      initial: {x: -0.10, y: 0.15, vx: 1.1}
      hand: {base: [0.0, 0.0]}
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from replay.params import ParamError, param


@dataclass
class StickParams:
    """The stick-shaped object (paper Sec. IV-A)."""

    mass: float = param(0.0225, unit="kg", gt=0, le=100, doc="m; paper: 22.5 g")
    inertia: float = param(
        3.2e-5, unit="kg*m^2", gt=0, le=100, doc="I about the centre of mass; paper: 32.0e3 g mm^2"
    )
    length: float = param(0.100, unit="m", gt=0, le=10, doc="L; paper: 100.0 mm")
    collision_width: float = param(
        0.0,
        unit="m",
        ge=0,
        le=1,
        doc="width the fingertips collide with; 0 = a segment, the paper's Assumption 5 "
        "(W ~ 0); the real stick is 0.010",
    )
    visual_width: float = param(
        0.010, unit="m", gt=0, le=1, doc="width the camera sees; paper: W = 10.0 mm"
    )
    thickness: float = param(
        0.005,
        unit="m",
        gt=0,
        le=1,
        doc="height above the table (visual only; not given in the paper)",
    )
    marker_length: float = param(
        0.080,
        unit="m",
        gt=0,
        le=10,
        doc="white marker on top, along the stick (size not given in the paper; assumed)",
    )
    marker_width: float = param(0.006, unit="m", gt=0, le=1, doc="white marker width (assumed)")
    restitution: float = param(
        0.19, unit="1", ge=0, le=1, doc="Newton's e between stick and fingertip; paper: 0.19"
    )
    friction: float = param(
        0.3, unit="1", ge=0, le=10, doc="Coulomb mu between stick and fingertip; paper: ~0.3"
    )


@dataclass
class InitialParams:
    """The stick's state at t = 0 (centre of mass, world frame = paper's Sigma_R)."""

    x: float = param(0.0, unit="m", ge=-10, le=10, doc="centre of mass x")
    y: float = param(0.25, unit="m", ge=-10, le=10, doc="centre of mass y")
    theta: float = param(
        0.0, unit="rad", ge=-100, le=100, doc="orientation of the stick's long axis x_B"
    )
    vx: float = param(0.0, unit="m/s", ge=-100, le=100, doc="translational velocity x")
    vy: float = param(0.0, unit="m/s", ge=-100, le=100, doc="translational velocity y")
    omega: float = param(
        0.0, unit="rad/s", ge=-1000, le=1000, doc="angular velocity (counter-clockwise > 0)"
    )


@dataclass
class ThrowParams:
    """A seeded random throw that replaces ``initial`` (``plants.airtable.throw``; our choice:
    the paper shows one throw per strategy). Left out of the resolved scenario while off."""

    random: bool = param(
        False, doc="draw the initial state from the run's seed instead of taking ``initial``"
    )
    speed: list[float] = param(
        [0.8, 1.4], unit="m/s", length=2, gt=0, le=100, doc="speed range (paper: 1.1 m/s)"
    )
    heading: list[float] = param(
        [-0.2617993877991494, 0.2617993877991494],
        unit="rad",
        length=2,
        ge=-3.15,
        le=3.15,
        doc="direction range from straight at the palm (-y); +-15 deg",
    )
    spin: list[float] = param(
        [4.0, 14.0],
        unit="rad/s",
        length=2,
        ge=0,
        le=1000,
        doc="spin magnitude range, either sign at equal odds (paper: ~10 rad/s)",
    )
    pass_x: list[float] = param(
        [-0.06, 0.06], unit="m", length=2, ge=-10, le=10, doc="x where the centre crosses pass_y"
    )
    pass_y: float = param(
        0.12, unit="m", ge=-10, le=10, doc="the line the centre crosses (paper: 0.12 m)"
    )
    pass_time: list[float] = param(
        [0.20, 0.35], unit="s", length=2, gt=0, le=100, doc="time from the start to pass_y"
    )

    def __post_init__(self) -> None:
        for name in ("speed", "heading", "spin", "pass_x", "pass_time"):
            lo, hi = getattr(self, name)
            if not lo <= hi:
                raise ParamError(name, f"lower bound {lo} above upper bound {hi}")

    def __bool__(self) -> bool:  # omit_empty: the resolved scenario shows it only when on
        return bool(self.random)


@dataclass
class HandParams:
    """XY slider base and two planar 2-joint fingers (paper Sec. IV-A)."""

    base_x_limits: list[float] = param(
        [-0.2, 0.2],
        unit="m",
        length=2,
        ge=-10,
        le=10,
        doc="slider travel in x about the table centre; paper: 400 mm",
    )
    base_y_limits: list[float] = param(
        [-0.2, 0.2],
        unit="m",
        length=2,
        ge=-10,
        le=10,
        doc="slider travel in y about the table centre; paper: 400 mm",
    )
    base_speed: float = param(
        1.0, unit="m/s", gt=0, le=100, doc="max speed per slider axis; paper: 1.0 m/s"
    )
    joint_speed: float = param(
        14.0, unit="rad/s", gt=0, le=1000, doc="max speed per joint; paper: 14.0 rad/s"
    )
    link_lengths: list[float] = param(
        [0.07, 0.07],
        unit="m",
        gt=0,
        le=1,
        length=2,
        doc="l1, l2 of both fingers (not in the paper; assumed)",
    )
    root_offset0: list[float] = param(
        [-0.03, 0.0],
        unit="m",
        length=2,
        ge=-1,
        le=1,
        doc="finger 0 root relative to the base (assumed)",
    )
    root_offset1: list[float] = param(
        [0.03, 0.0],
        unit="m",
        length=2,
        ge=-1,
        le=1,
        doc="finger 1 root relative to the base (assumed)",
    )
    q1_limits: list[float] = param(
        [-math.pi, math.pi],
        unit="rad",
        length=2,
        ge=-10,
        le=10,
        doc="first joint range, both fingers (assumed)",
    )
    q2_limits: list[float] = param(
        [-2.6, 2.6],
        unit="rad",
        length=2,
        ge=-10,
        le=10,
        doc="second joint range, both fingers (assumed)",
    )
    tip_radius: float = param(0.005, unit="m", gt=0, le=0.5, doc="fingertip disc radius (assumed)")
    tip_height: float = param(0.020, unit="m", gt=0, le=1, doc="fingertip cylinder height (visual)")
    base: list[float] = param(
        [0.0, 0.0], unit="m", length=2, ge=-10, le=10, doc="initial base position"
    )
    joints0: list[float] = param(
        [2.0, -1.0], unit="rad", length=2, ge=-10, le=10, doc="initial (q1, q2) of finger 0"
    )
    joints1: list[float] = param(
        [math.pi - 2.0, 1.0],
        unit="rad",
        length=2,
        ge=-10,
        le=10,
        doc="initial (q1, q2) of finger 1",
    )

    def __post_init__(self) -> None:
        for name in ("base_x_limits", "base_y_limits", "q1_limits", "q2_limits"):
            lo, hi = getattr(self, name)
            if not lo <= hi:
                raise ParamError(name, f"lower limit {lo} above upper limit {hi}")
        for i, (name, lims) in enumerate((("x", self.base_x_limits), ("y", self.base_y_limits))):
            if not lims[0] <= self.base[i] <= lims[1]:
                raise ParamError(
                    f"base[{i}]",
                    f"initial {name} = {self.base[i]} outside base_{name}_limits {list(lims)}",
                )
        for k, q in enumerate((self.joints0, self.joints1)):
            for j, lims in enumerate((self.q1_limits, self.q2_limits)):
                if not lims[0] <= q[j] <= lims[1]:
                    raise ParamError(
                        f"joints{k}[{j}]", f"q{j + 1} = {q[j]} outside q{j + 1}_limits {list(lims)}"
                    )


@dataclass
class SolverParams:
    """Pymunk (Chipmunk2D) settings. Pymunk's defaults are tuned for pixel units and games."""

    iterations: int = param(
        30, unit="1", ge=1, le=1000, doc="impulse-solver iterations per step (Pymunk default 10)"
    )
    collision_slop: float = param(
        1e-6,
        unit="m",
        ge=0,
        le=0.1,
        doc="penetration allowed before position correction (Pymunk default 0.1, meant for pixels)",
    )
    collision_bias: float = param(
        0.9**60,
        unit="1",
        gt=0,
        lt=1,
        doc="fraction of overlap left uncorrected after 1 s (Pymunk "
        "default); corrects positions only, never velocities",
    )


@dataclass
class Params:
    stick: StickParams = field(
        default_factory=StickParams, metadata={"doc": "the object", "unit": ""}
    )
    initial: InitialParams = field(
        default_factory=InitialParams, metadata={"doc": "the object's initial state", "unit": ""}
    )
    throw: ThrowParams = field(
        default_factory=ThrowParams,
        metadata={
            "doc": "a seeded random initial state (off: ``initial``)",
            "unit": "",
            "omit_empty": True,
        },
    )
    hand: HandParams = field(
        default_factory=HandParams, metadata={"doc": "slider base and fingers", "unit": ""}
    )
    solver: SolverParams = field(
        default_factory=SolverParams, metadata={"doc": "Pymunk settings", "unit": ""}
    )
    rest_speed: float = param(
        0.005, unit="m/s", gt=0, le=10, doc="'rest' when the stick is slower than this ..."
    )
    rest_omega: float = param(
        0.1, unit="rad/s", gt=0, le=100, doc="... and turns slower than this ..."
    )
    rest_time: float = param(0.05, unit="s", gt=0, le=600, doc="... for this long")
    hold_speed: float = param(
        0.02,
        unit="m/s",
        gt=0,
        le=10,
        doc="the outcome's 'captured': the stick slower than this ...",
    )
    hold_omega: float = param(
        0.5, unit="rad/s", gt=0, le=100, doc="... turning slower than this ..."
    )
    hold_gap: float = param(
        0.003,
        unit="m",
        ge=0,
        le=0.1,
        doc="... with a fingertip on each face, its centre within W/2 + "
        "tip_radius + this of the stick's axis and between its ends ...",
    )
    hold_time: float = param(
        0.05,
        unit="s",
        gt=0,
        le=600,
        doc="... for this long at the end of the run (our choice; the "
        "paper defines no capture test)",
    )
