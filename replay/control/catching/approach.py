"""What eq. 25 leaves out: the direction the ball comes into the hand (an optional extension).

Eq. 4 fixes r_e(t_c) = r_e'(t_c) = 0 for every alpha (b and db/dq vanish at q_i = q_alpha, eq. 8).
Near the catch the ball, seen from the desired hand point l(q_d), is then at

    r_o - l(q_d) = -r_e(t) ~ -1/2 r_e''(t_c) (t - t_c)^2,

so it comes in along the ray -r_e''(t_c), whatever the sign of t - t_c: the approach direction is
the direction of the relative acceleration at t_c,

    r_e''(t_c) = J_l(q_o) q_d''(t_c) + q_d'^T H_l q_d' - r_o'',   q_d'' = q_o'' + m2 alpha,

(q_d'(t_c) = J_c^-1 r_o' is fixed by eq. 4; m2 carries the (q_i - q_alpha)^2 terms of eq. 12, so
r_e''(t_c) is *linear* in alpha). Eqs. 13-25 do not see it: eq. 25 weighs tau and omega only.
For a catch the ball must come down the palm axis (from +n, n the palm normal at the catch
posture), i.e. r_e''(t_c) parallel to -n. The extension adds to eq. 25

    E_app = w_app * n_per_throw * sum_throws |(I - n n^T) r_e''(t_c)|^2 / a0^2,

a0 the median |r_e''(t_c)| of the initial alpha over the throws (so each term is ~ sin^2 of the
approach angle off the palm axis), n_per_throw = samples per throw (each throw's catch counts as
much as its whole sampled flight in eq. 25's sum). Not in the paper: off unless
``approach_weight`` > 0 (scenario catch_optimised_approach).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from replay.control.catching.mapping import DirectMapping, Features
from replay.control.catching.model import ArmModel


@dataclass
class ApproachTerm:
    normal: np.ndarray  # (k, 3) palm normal at each catch sample
    P: np.ndarray  # (k, 3, 3) I - n n^T
    h0: np.ndarray  # (k, 3) r_e''(t_c) at alpha = 0
    G: np.ndarray  # (k, 3, n_alpha) d r_e''(t_c) / d alpha
    a0: float  # m/s^2, the normaliser
    weight: float  # w_app * n_per_throw

    def accel(self, alpha) -> np.ndarray:
        """r_e''(t_c) per catch sample, (k, 3)."""
        return self.h0 + self.G @ np.asarray(alpha, float)

    def residuals(self, alpha) -> np.ndarray:
        lat = np.einsum("kij,kj->ki", self.P, self.accel(alpha))
        return (np.sqrt(self.weight) / self.a0 * lat).ravel()

    def jacobian(self) -> np.ndarray:
        return (np.sqrt(self.weight) / self.a0 * np.einsum("kij,kjn->kin", self.P, self.G)).reshape(
            -1, self.G.shape[-1]
        )

    def cost(self, alpha) -> float:
        r = self.residuals(alpha)
        return float(r @ r)

    def angles(self, alpha) -> np.ndarray:
        """Degrees between the ball's approach (-r_e'') and the palm normal, per catch sample."""
        a = -self.accel(alpha)
        c = np.einsum("ki,ki->k", a, self.normal) / np.linalg.norm(a, axis=1)
        return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))


def approach_term(
    mapping: DirectMapping,
    model: ArmModel,
    feats: Features,
    catch_idx,
    gravity,
    alpha0,
    weight: float,
) -> ApproachTerm:
    """The term over the catch samples ``catch_idx`` of ``feats`` (q4 = q_alpha there)."""
    idx = np.asarray(catch_idx, int)
    nm, m = mapping.poly.n_mono, mapping.poly.m
    g = np.asarray(gravity, float)
    normals, accs, grads = [], [], []
    for k in idx:
        p, pd, pdd = feats.p[k], feats.pd[k], feats.pdd[k]
        acc, J = model.point_acceleration(p, pd, pdd)  # b = 0, q_d' = q_o' at t_c
        normals.append(model.tool_axis(p))
        accs.append(acc - g)  # r_o'' = g
        # d(J m2 A)/dA[j, c] = J[:, c] m2_j  ->  alpha index j * m + c (row-major A)
        grads.append(np.einsum("ic,j->ijc", J, feats.m2[k]).reshape(3, nm * m))
    normal, h0, G = np.array(normals), np.array(accs), np.array(grads)
    P = np.eye(3)[None] - np.einsum("ki,kj->kij", normal, normal)
    a0 = float(np.median(np.linalg.norm(h0 + G @ np.asarray(alpha0, float), axis=1)))
    return ApproachTerm(normal, P, h0, G, a0, float(weight))
