"""The catching problem assembled: l_c, b, the throw set, C alpha = rhs (eq. 13) and E (eq. 25)."""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from replay.control.catching.mapping import CatchGeometry, DirectMapping, PolynomialB
from replay.control.catching.model import ArmModel
from replay.control.catching.approach import approach_term
from replay.control.catching.optimise import Objective, OptimResult, initial_alpha, optimise
from replay.control.catching.trajectories import ThrowSet, launch_velocity, throw_set


@dataclass
class ProblemConfig:
    q_alpha: float = math.pi / 2  # catching angle of joint 4 (Sec. IV-A)
    order: int = 4  # N of eq. 12 (Sec. IV-B: 4th order)
    q_start: tuple = (0.0, math.pi / 4, 0.0, 0.0)  # q(t0), full 4 joints (Sec. IV-A)
    catch_q: tuple = (0.0, math.pi / 4)  # (q1, q2) of the nominal catching point
    throw_start: tuple = (3.2, 0.0, 1.0)  # r_o(t0) of every throw of the set (m)
    speeds: tuple = (8.0, 9.0, 10.0)  # launch speeds (m/s), Sec. IV-B "8 ~ 10 m/s"
    spread: float = 0.1  # half-width of the arrival grid (m)
    grid: int = 3  # arrival grid is grid x grid
    n_samples: int = 15  # samples per throw, t0 .. arrival
    gravity: float = 9.81
    tau_max: tuple = (60.0, 60.0, 30.0)  # |tau| limits of joints 1, 2, 4 (N*m)
    omega_max: tuple = (6.0, 6.0, 10.0)  # |omega| limits of joints 1, 2, 4 (rad/s)
    w_tau: float = 1.0  # K_tau = w_tau diag(1 / tau_max^2)
    w_omega: float = 1.0  # K_omega = w_omega diag(1 / omega_max^2)
    penalty: float = 100.0  # weight of the limit hinge penalties
    torque_penalty: float = -1.0  # of eq. 22's alone; < 0 = ``penalty``
    approach_weight: float = 0.0  # w_app of the extension (approach.py); 0 = off
    max_iter: int = 40
    # the extension (not in the paper, optimise.Objective): "eq25" weighs the unclamped eq.-17
    # torque as the paper states; "clamped" weighs sat(tau) + excess_weight (tau - sat(tau))
    torque_cost: str = "eq25"
    excess_weight: float = 0.1

    _KEY_DEFAULTS = {"torque_cost": "eq25", "excess_weight": 0.1}  # not keyed at these values

    def key(self, model: ArmModel | None = None) -> str:
        """A short hash of everything the optimum depends on: this config and, if given, the
        model (its catch point and mass matrix at two postures, rounded)."""
        data = {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}
        if self.torque_cost == "eq25":  # keys of eq.-25 configurations as before the extension
            for k in self._KEY_DEFAULTS:
                data.pop(k)
        if model is not None:
            probe = []
            for p in ((0.0, math.pi / 4, 0.0), (0.3, 0.5, 1.2)):
                probe += model.point(np.array(p)).round(9).tolist()
                probe += model.mass(np.array(p)).round(9).ravel().tolist()
                probe += model.gravity_full(model.full(np.array(p))).round(9).tolist()
            data["model"] = probe
        return hashlib.sha1(json.dumps(data, sort_keys=True).encode()).hexdigest()[:16]


@dataclass
class CatchingProblem:
    config: ProblemConfig
    model: ArmModel
    geometry: CatchGeometry
    poly: PolynomialB
    mapping: DirectMapping
    throws: ThrowSet
    catch_point: np.ndarray
    nominal_velocity: np.ndarray
    C: np.ndarray
    rhs: np.ndarray
    objective: Objective
    result: OptimResult | None = field(default=None)

    def solve(self, progress=None) -> OptimResult:
        self.result = optimise(
            self.objective, self.C, self.rhs, max_iter=self.config.max_iter, progress=progress
        )
        return self.result


def build_problem(model: ArmModel, cfg: ProblemConfig | None = None) -> CatchingProblem:
    cfg = cfg or ProblemConfig()
    act = model.active
    q_start = np.asarray(cfg.q_start, float)
    geo = CatchGeometry.from_fk(
        lambda q: model.fk(_with_fixed(model, q)), cfg.q_alpha, p_ref=cfg.catch_q
    )
    poly = PolynomialB(cfg.order, cfg.q_alpha, n_joints=len(act), selected=len(act) - 1)
    mapping = DirectMapping(geo, poly)
    catch_point = model.point(np.array([cfg.catch_q[0], cfg.catch_q[1], cfg.q_alpha]))
    g = (0.0, 0.0, -cfg.gravity)
    throws = throw_set(
        cfg.throw_start,
        catch_point,
        geo.origin,
        geo.catch_radius,
        cfg.speeds,
        cfg.spread,
        cfg.grid,
        cfg.n_samples,
        g,
    )
    nominal_v, _ = launch_velocity(
        cfg.throw_start, throws.throws[throws.nominal].arrival, cfg.speeds[len(cfg.speeds) // 2], g
    )
    C, rhs = mapping.constraint(cfg.throw_start, nominal_v, q_start[act])  # eqs. 13-14
    r, rd, rdd = throws.stacked()
    feats = mapping.features(r, rd, rdd)
    if not np.all(feats.in_domain):
        raise ValueError("a sampled throw leaves the domain of l_c^-1")
    approach = None
    if cfg.approach_weight > 0.0:  # not in the paper: see approach.py
        last = np.arange(cfg.n_samples - 1, len(r), cfg.n_samples)  # t_c of every throw
        approach = approach_term(
            mapping,
            model,
            feats,
            last,
            g,
            initial_alpha(C, rhs),
            cfg.approach_weight * cfg.n_samples,
        )
    obj = Objective(
        mapping,
        model,
        feats,
        cfg.tau_max,
        cfg.omega_max,
        cfg.w_tau,
        cfg.w_omega,
        cfg.penalty,
        approach,
        cfg.torque_penalty if cfg.torque_penalty >= 0 else None,
        clamped=cfg.torque_cost == "clamped",
        excess_weight=cfg.excess_weight,
    )
    return CatchingProblem(
        cfg, model, geo, poly, mapping, throws, catch_point, nominal_v, C, rhs, obj
    )


def _with_fixed(model: ArmModel, q: np.ndarray) -> np.ndarray:
    """Geometry extraction moves joints 1, 2, 4 only; joint 3 keeps the model's fixed value."""
    q = np.asarray(q, float).copy()
    locked = [i for i in range(model.n) if i not in set(model.active.tolist())]
    q[locked] = model.q_fixed[locked]
    return q
