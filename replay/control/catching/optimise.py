"""Offline optimisation of the mapping parameters alpha (eq. 25), pure NumPy.

    min_alpha E(alpha) = sum_samples tau^T K_tau tau + omega^T K_omega omega          (eq. 25)
    s.t.  C alpha = [q(t0) - q_o(t0); qd(t0) - qd_o(t0)]                              (eq. 13)
          tau_min <= tau <= tau_max (eq. 22),  omega_min <= omega <= omega_max         (eq. 24)

- Equality (eq. 13): exact, by the null-space parametrisation alpha = alpha0 + Z beta, with
  alpha0 = C^+ rhs (minimum norm) and Z an orthonormal basis of ker C.
- Limits (eqs. 22, 24): symmetric |tau_i| <= tau_max_i, |omega_i| <= omega_max_i, as quadratic
  hinge *penalties* w_pen * sum max(0, |x_i|/x_max_i - 1)^2 (soft constraints; the report says
  whether the optimum violates them).
- Solver: Levenberg-Marquardt on the residual vector [K_tau^1/2 tau; K_omega^1/2 omega; hinge],
  Marquardt scaling. omega = qd_o + m1 A is linear in alpha (eq. 23), so its Jacobian is exact;
  tau(q_d, qd_d, qdd_d) (eq. 17) is differentiated through the chain rule, d tau/dq and
  d tau/dqd by forward differences of the model's inverse dynamics, d tau/dqdd = M.
- l_c^-1 does not depend on alpha, so q_o and its derivatives along every sample are computed once.
Deterministic: fixed sample set, no randomness.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from replay.control.catching.mapping import DirectMapping, Features
from replay.control.catching.model import ArmModel


@dataclass
class CostRecord:
    iteration: int
    torque_cost: float  # sum tau^T K_tau tau
    velocity_cost: float  # sum omega^T K_omega omega
    penalty: float  # limit hinge penalty (eqs. 22, 24)
    objective: float  # torque_cost + velocity_cost + penalty
    max_torque_ratio: float  # max_i,samples |tau_i| / tau_max_i
    max_velocity_ratio: float
    approach_cost: float = 0.0  # the optional approach-direction term (approach.py), in objective


@dataclass
class OptimResult:
    alpha: np.ndarray
    alpha0: np.ndarray
    history: list = field(default_factory=list)
    constraint_residual: float = 0.0
    wall_time: float = 0.0
    n_samples: int = 0


def initial_alpha(C: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """The paper's 'initial parameters': the minimum-norm alpha with C alpha = rhs (eq. 13)."""
    return np.linalg.pinv(C, rcond=1e-12) @ rhs


def null_space(C: np.ndarray) -> np.ndarray:
    _, s, Vt = np.linalg.svd(C)
    rank = int(np.sum(s > s[0] * 1e-12))
    return Vt[rank:].T


def project_eq13(alpha: np.ndarray, C: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """The alpha nearest ``alpha`` (Euclidean) that meets C alpha = rhs (eq. 13): an alpha made
    for other throws, re-solved for this set's initial constraint with no cost (a falsifier)."""
    alpha = np.asarray(alpha, float)
    return alpha + np.linalg.pinv(C, rcond=1e-12) @ (rhs - C @ alpha)


def null_space_alpha(C: np.ndarray, rhs: np.ndarray, size: float, seed: int) -> np.ndarray:
    """alpha0 + Z beta (eq. 13 exact) with beta a seeded random direction and |Z beta| = size:
    an alpha as far from the initial one as an optimum may be, chosen with no cost (a falsifier)."""
    Z = null_space(C)
    beta = np.random.default_rng(seed).standard_normal(Z.shape[1])
    return initial_alpha(C, rhs) + Z @ (size * beta / np.linalg.norm(beta))


class Objective:
    """E(alpha) of eq. 25 over fixed samples, with its residuals and Jacobian (plus, optionally, the
    approach-direction term of approach.py, which is not in the paper)."""

    def __init__(
        self,
        mapping: DirectMapping,
        model: ArmModel,
        feats: Features,
        tau_max,
        omega_max,
        w_tau: float = 1.0,
        w_omega: float = 1.0,
        penalty: float = 100.0,
        approach=None,
        torque_penalty: float | None = None,
        clamped: bool = False,
        excess_weight: float = 0.1,
    ) -> None:
        self.mp, self.model, self.f = mapping, model, feats
        self.approach = approach  # ApproachTerm or None (eq. 25 as stated)
        self.tau_max = np.asarray(tau_max, float)
        self.omega_max = np.asarray(omega_max, float)
        self.kt = w_tau / self.tau_max**2  # K_tau = diag(w_tau / tau_max^2)
        self.kw = w_omega / self.omega_max**2  # K_omega = diag(w_omega / omega_max^2)
        self.wp = penalty  # hinge weight of eq. 24 (omega)
        self.wpt = penalty if torque_penalty is None else torque_penalty  # of eq. 22 (tau)
        self.nm, self.m = mapping.poly.n_mono, mapping.poly.m
        # The extension (not in the paper): weigh the torque the arm can deliver, sat(tau) at
        # +-tau_max, plus excess_weight times the undeliverable rest tau - sat(tau) (the
        # saturated tracking error's cause), instead of eq. 25's unclamped tau.
        self.clamped = clamped
        self.we = excess_weight

    def trajectory(self, alpha):
        A = np.asarray(alpha).reshape(self.nm, self.m)
        f = self.f
        return f.p + f.m @ A, f.pd + f.m1 @ A, f.pdd + f.m2 @ A  # eqs. 7, 23, 16

    def torques(self, alpha) -> np.ndarray:
        q, qd, qdd = self.trajectory(alpha)
        return np.array([self.model.tau(a, b, c) for a, b, c in zip(q, qd, qdd)])  # eq. 17

    def _split(self, tau):
        """(sat(tau), tau - sat(tau)) at +-tau_max."""
        sat = np.clip(tau, -self.tau_max, self.tau_max)
        return sat, tau - sat

    def _torque_residuals(self, tau) -> list:
        if not self.clamped:
            return [(np.sqrt(self.kt) * tau).ravel()]
        sat, exc = self._split(tau)
        return [(np.sqrt(self.kt) * sat).ravel(), (np.sqrt(self.we * self.kt) * exc).ravel()]

    def _parts(self, tau, omega):
        ht = np.maximum(np.abs(tau) / self.tau_max - 1.0, 0.0)
        hw = np.maximum(np.abs(omega) / self.omega_max - 1.0, 0.0)
        return ht, hw

    def record(self, it: int, alpha, tau=None) -> CostRecord:
        tau = self.torques(alpha) if tau is None else tau
        _, omega, _ = self.trajectory(alpha)
        tc = float(np.sum(self.kt * tau**2))  # eq. 25's torque cost, also for the extension
        vc = float(np.sum(self.kw * omega**2))
        ht, hw = self._parts(tau, omega)
        pen = float(self.wpt * np.sum(ht**2) + self.wp * np.sum(hw**2))
        ac = self.approach.cost(alpha) if self.approach is not None else 0.0
        obj_t = tc
        if self.clamped:
            sat, exc = self._split(tau)
            obj_t = float(np.sum(self.kt * sat**2) + self.we * np.sum(self.kt * exc**2))
        return CostRecord(
            it,
            tc,
            vc,
            pen,
            obj_t + vc + pen + ac,
            float(np.max(np.abs(tau) / self.tau_max)),
            float(np.max(np.abs(omega) / self.omega_max)),
            ac,
        )

    def residuals(self, alpha, tau=None):
        tau = self.torques(alpha) if tau is None else tau
        _, omega, _ = self.trajectory(alpha)
        ht, hw = self._parts(tau, omega)
        sp, spt = np.sqrt(self.wp), np.sqrt(self.wpt)
        parts = self._torque_residuals(tau) + [
            (np.sqrt(self.kw) * omega).ravel(),
            spt * ht.ravel(),
            sp * hw.ravel(),
        ]
        if self.approach is not None:
            parts.append(self.approach.residuals(alpha))
        return np.concatenate(parts), tau

    def jacobian(self, alpha):
        """Residuals, torques and d residuals / d alpha (rows as in :meth:`residuals`)."""
        q, qd, qdd = self.trajectory(alpha)
        n = len(q)
        tau = np.empty((n, self.m))
        Tq = np.empty((n, self.m, self.m))
        Tqd, M = np.empty_like(Tq), np.empty_like(Tq)
        for k in range(n):
            tau[k], Tq[k], Tqd[k], M[k] = self.model.tau_and_partials(q[k], qd[k], qdd[k])
        f = self.f
        # d tau_i / d A[j, k] = Tq[i, k] m_j + Tqd[i, k] m1_j + M[i, k] m2_j
        Jt = (
            np.einsum("nj,nik->nijk", f.m, Tq)
            + np.einsum("nj,nik->nijk", f.m1, Tqd)
            + np.einsum("nj,nik->nijk", f.m2, M)
        ).reshape(n, self.m, -1)
        Jw = np.einsum("nj,ik->nijk", f.m1, np.eye(self.m)).reshape(n, self.m, -1)
        omega = qd
        ht, hw = self._parts(tau, omega)
        sp, spt = np.sqrt(self.wp), np.sqrt(self.wpt)
        Jht = (ht > 0)[..., None] * (np.sign(tau) / self.tau_max)[..., None] * Jt
        Jhw = (hw > 0)[..., None] * (np.sign(omega) / self.omega_max)[..., None] * Jw
        if self.clamped:
            inside = (np.abs(tau) <= self.tau_max)[..., None]
            Jtau = [
                (np.sqrt(self.kt)[:, None] * (inside * Jt)).reshape(-1, Jt.shape[-1]),
                (np.sqrt(self.we * self.kt)[:, None] * (~inside * Jt)).reshape(-1, Jt.shape[-1]),
            ]
        else:
            Jtau = [(np.sqrt(self.kt)[:, None] * Jt).reshape(-1, Jt.shape[-1])]
        J = np.concatenate(
            Jtau
            + [
                (np.sqrt(self.kw)[:, None] * Jw).reshape(-1, Jw.shape[-1]),
                spt * Jht.reshape(-1, Jt.shape[-1]),
                sp * Jhw.reshape(-1, Jw.shape[-1]),
            ]
            + ([self.approach.jacobian()] if self.approach is not None else [])
        )
        r, _ = self.residuals(alpha, tau)
        return r, tau, J


def optimise(
    objective: Objective,
    C: np.ndarray,
    rhs: np.ndarray,
    *,
    max_iter: int = 30,
    rtol: float = 1e-5,
    lam0: float = 1e-3,
    progress=None,
) -> OptimResult:
    """Levenberg-Marquardt over beta, alpha = alpha0 + Z beta (see the module doc)."""
    t_start = time.perf_counter()
    alpha0 = initial_alpha(C, rhs)
    Z = null_space(C)
    beta = np.zeros(Z.shape[1])
    alpha = alpha0.copy()
    r, tau, Ja = objective.jacobian(alpha)
    cost = float(r @ r)
    hist = [objective.record(0, alpha, tau)]
    if progress:
        progress(hist[-1])
    lam = lam0
    for it in range(1, max_iter + 1):
        J = Ja @ Z
        JtJ = J.T @ J
        g = J.T @ r
        D = np.maximum(np.diag(JtJ), 1e-12 * max(1.0, float(np.max(np.diag(JtJ)))))
        accepted = False
        for _ in range(12):
            step = np.linalg.solve(JtJ + lam * np.diag(D), -g)
            a_new = alpha0 + Z @ (beta + step)
            r_new, tau_new = objective.residuals(a_new)
            c_new = float(r_new @ r_new)
            if c_new < cost:
                accepted = True
                break
            lam *= 4.0
        if not accepted:
            break
        rel = (cost - c_new) / cost
        beta, alpha, cost = beta + step, a_new, c_new
        lam = max(lam / 3.0, 1e-9)
        hist.append(objective.record(it, alpha, tau_new))
        if progress:
            progress(hist[-1])
        if rel < rtol:
            break
        r, tau, Ja = objective.jacobian(alpha)
    res = OptimResult(
        alpha=alpha,
        alpha0=alpha0,
        history=hist,
        constraint_residual=float(np.max(np.abs(C @ alpha - rhs))),
        wall_time=time.perf_counter() - t_start,
        n_samples=len(objective.f.p),
    )
    return res


def save_alpha(path, result: OptimResult, meta: dict) -> None:
    """A small JSON: alpha (optimised), alpha0 (initial), the cost history and what they are for."""
    data = {
        "alpha": np.asarray(result.alpha).tolist(),
        "alpha0": result.alpha0.tolist(),
        "history": [asdict(h) for h in result.history],
        "constraint_residual": result.constraint_residual,
        "meta": meta,
    }
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(data, fh, indent=1, allow_nan=False)


def load_alpha(path) -> dict:
    with open(path, encoding="utf-8") as fh:
        data = json.load(fh)
    data["alpha"] = np.asarray(data["alpha"], float)
    data["alpha0"] = np.asarray(data["alpha0"], float)
    data["history"] = [CostRecord(**h) for h in data["history"]]
    return data
