"""The direct mapping q_d = f(r_o) = g o l_c^-1(r_o) of Namiki & Ishikawa (eqs. 6-8, 12-14, 16, 23).

NumPy, batched: every function takes arrays with a leading sample axis ``(n, ...)``; the
controller's one-sample path (``*_one``) is in Python floats.

Coordinates. The arm has four joints; the paper uses axes 1, 2 and 4 and holds axis 3 at 0
(Sec. IV-A). The mapping works in the *active* coordinates ``p = (q1, q2, q4)`` (m_q = 3); the
selected joint i of eq. 6 is q4 (``p[2]``) with catching angle q_alpha, and ``s = q4 - q_alpha``.

Linearised kinematics (eq. 6). l_c(q) = l(q)|_{q4=q_alpha} + dl/dq4|_{q4=q_alpha} (q4 - q_alpha).
For an arm whose first two axes intersect at a shoulder point O (the WAM: J1 vertical, J2
horizontal, both through the shoulder) and with q3 = 0, the product-of-exponentials form gives the
closed form

    l_c(q1, q2, q4) = O + R(w1, q1) R(w2, q2) (c + t s),

with c = l([0,0,0,q_alpha]) - O the catch point seen from the shoulder in the zero pose and
t = dl/dq4 there. All of O, w1, w2, c, t are extracted from the model's forward kinematics only
(:meth:`CatchGeometry.from_fk`), and the closed form is checked against eq. 6 at start-up.

Inverse l_c^-1 (closed form). |c + t s| = |r - O| is a quadratic in s; its branch through s = 0
(the catch point) is taken, then (q1, q2) solve the two-axis rotation problem (Paden-Kahan
subproblem 2), the solution nearest the reference posture. Domain: |r - O| >= d_min, the distance
of the shoulder from the tangent line {c + t s}. Outside it the target is *clamped* to the nearest
reachable radius (s at the closest point of the line, direction kept) and ``in_domain`` is False.
Targets on the J1 axis leave q1 undetermined (q1 is taken from the reference, flagged too).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np


ACTIVE = (0, 1, 3)  # active joints of the 4-DOF arm (axes 1, 2, 4); axis 3 held at 0


def full_q(p: np.ndarray) -> np.ndarray:
    """Active (…, 3) -> full 4-joint (…, 4) vector with q3 = 0."""
    p = np.asarray(p, dtype=float)
    out = np.zeros(p.shape[:-1] + (4,))
    out[..., ACTIVE] = p
    return out


def _skew(w: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def _rot(K: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Rodrigues, batched: R[n] = I + sin(th) K + (1 - cos(th)) K^2, shape (n, 3, 3)."""
    th = np.asarray(theta, dtype=float)[:, None, None]
    return np.eye(3) + np.sin(th) * K + (1.0 - np.cos(th)) * (K @ K)


def _circle(p0, p1, p2):
    """Centre and unit normal of the circle through p0 -> p1 -> p2 (normal by the right hand)."""
    a, b = p1 - p0, p2 - p0
    n = np.cross(a, b)
    nn = float(n @ n)
    if nn < 1e-18:
        raise ValueError("degenerate circle: the tool point lies on a joint axis")
    centre = p0 + (np.cross(n, a) * (b @ b) + np.cross(b, n) * (a @ a)) / (2.0 * nn)
    return centre, n / math.sqrt(nn)


def _wrap_near(x, ref):
    return ref + (np.asarray(x) - ref + np.pi) % (2.0 * np.pi) - np.pi


@dataclass
class InverseResult:
    p: np.ndarray  # (n, 3) active joint angles q_o = l_c^-1(r_o)
    in_domain: np.ndarray  # (n,) bool: False where the target was clamped (or q1 undetermined)


class CatchGeometry:
    """l_c of eq. 6 in closed form, its inverse and its first and second derivatives."""

    def __init__(self, origin, w1, w2, c, t, q_alpha: float, p_ref=(0.0, math.pi / 4)) -> None:
        self.origin = np.asarray(origin, float)
        self.w1 = np.asarray(w1, float)
        self.w2 = np.asarray(w2, float)
        self.c = np.asarray(c, float)
        self.t = np.asarray(t, float)
        self.q_alpha = float(q_alpha)
        self.p_ref = np.asarray(p_ref, float)  # (q1, q2) the inverse prefers (branch choice)
        self.K1, self.K2 = _skew(self.w1), _skew(self.w2)
        a, b = self.t @ self.t, self.c @ self.t
        self._a, self._b = float(a), float(b)
        self._sigma = 1.0 if b >= 0.0 else -1.0  # branch with s = 0 at |r - O| = |c|
        self.s_min_dist = -b / a  # s at the line's closest point to O
        self.d_min = float(np.linalg.norm(self.c + self.t * self.s_min_dist))
        self.catch_radius = float(np.linalg.norm(self.c))
        # the same constants as 3-tuples of floats for the one-sample path (*_one)
        self._f = tuple(tuple(x.tolist()) for x in (self.origin, self.w1, self.w2, self.c, self.t))
        self._x = _cross3(self._f[1], self._f[2])

    @classmethod
    def from_fk(cls, fk, q_alpha: float, p_ref=(0.0, math.pi / 4), check: bool = True):
        """Extract O, w1, w2, c, t from tool-position forward kinematics fk(q4vec) -> (3,)."""
        ang = (0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0)

        def pts(k):
            out = []
            for th in ang:
                q = np.array([0.0, 0.0, 0.0, q_alpha])
                q[k] += th
                out.append(np.asarray(fk(q), float))
            return out

        c1, w1 = _circle(*pts(0))
        c2, w2 = _circle(*pts(1))
        c4, w4 = _circle(*pts(3))
        # shoulder O: closest points of the J1 and J2 axis lines (they must meet)
        d = c2 - c1
        w12 = w1 @ w2
        den = 1.0 - w12 * w12
        if den < 1e-12:
            raise ValueError("J1 and J2 axes are parallel: the closed-form l_c needs a shoulder")
        lam1 = (d @ w1 - w12 * (d @ w2)) / den
        lam2 = (w12 * (d @ w1) - d @ w2) / den
        o1, o2 = c1 + lam1 * w1, c2 + lam2 * w2
        if np.linalg.norm(o1 - o2) > 1e-7:
            raise ValueError("J1 and J2 axes do not intersect: closed-form l_c does not apply")
        origin = 0.5 * (o1 + o2)
        P = np.asarray(fk(np.array([0.0, 0.0, 0.0, q_alpha])), float)
        t = np.cross(w4, P - c4)  # dl/dq4 at the zero pose
        geo = cls(origin, w1, w2, P - origin, t, q_alpha, p_ref)
        if check:
            geo.check_against_fk(fk)
        return geo

    # --- eq. 6 ----------------------------------------------------------------------------
    def lc(self, p) -> np.ndarray:
        """l_c(p), p (n, 3) -> (n, 3)."""
        p = np.atleast_2d(np.asarray(p, float))
        R = _rot(self.K1, p[:, 0]) @ _rot(self.K2, p[:, 1])
        w = self.c + self.t * (p[:, 2:3] - self.q_alpha)
        return self.origin + np.einsum("nij,nj->ni", R, w)

    def lc_eq6(self, fk, p, h: float = 1e-6) -> np.ndarray:
        """Eq. 6 literally, from fk and a central difference of dl/dq4 (for checks)."""
        out = []
        for pi in np.atleast_2d(p):
            q = full_q(pi)
            q[3] = self.q_alpha
            e = np.zeros(4)
            e[3] = h
            dl = (np.asarray(fk(q + e)) - np.asarray(fk(q - e))) / (2 * h)
            out.append(np.asarray(fk(q)) + dl * (pi[2] - self.q_alpha))
        return np.array(out)

    def check_against_fk(self, fk, tol: float = 1e-6) -> None:
        rng = np.random.default_rng(0)
        P = np.column_stack(
            [rng.uniform(-1, 1, 5), rng.uniform(-1, 1.5, 5), self.q_alpha + rng.uniform(-1, 1, 5)]
        )
        err = np.abs(self.lc(P) - self.lc_eq6(fk, P)).max()
        if err > tol:
            raise ValueError(f"closed-form l_c differs from eq. 6 by {err:.3g} m")

    def derivatives(self, p):
        """l_c, its Jacobian J[n, :, k] = dl_c/dp_k and Hessian H[n, :, k, l] (n, 3, 3, 3)."""
        p = np.atleast_2d(np.asarray(p, float))
        n = len(p)
        R1, R2 = _rot(self.K1, p[:, 0]), _rot(self.K2, p[:, 1])
        K1, K2 = self.K1, self.K2
        w = self.c + self.t * (p[:, 2:3] - self.q_alpha)
        R2w = np.einsum("nij,nj->ni", R2, w)
        R2t = np.einsum("nij,j->ni", R2, self.t)
        K2R2w, K2R2t = R2w @ K2.T, R2t @ K2.T
        ap = lambda A, x: np.einsum("nij,nj->ni", A, x)  # noqa: E731
        v = ap(R1, R2w)
        d1 = v @ K1.T
        d2 = ap(R1, K2R2w)
        d3 = ap(R1, R2t)
        J = np.stack([d1, d2, d3], axis=2)
        H = np.zeros((n, 3, 3, 3))
        H[:, :, 0, 0] = d1 @ K1.T
        H[:, :, 0, 1] = H[:, :, 1, 0] = d2 @ K1.T
        H[:, :, 0, 2] = H[:, :, 2, 0] = d3 @ K1.T
        H[:, :, 1, 1] = ap(R1, K2R2w @ K2.T)
        H[:, :, 1, 2] = H[:, :, 2, 1] = ap(R1, K2R2t)
        return self.origin + v, J, H

    # --- l_c^-1 ------------------------------------------------------------------------------
    def inverse(self, r) -> InverseResult:
        """q_o = l_c^-1(r_o) (closed form), r (n, 3). See the module doc for the domain."""
        r = np.atleast_2d(np.asarray(r, float))
        v = r - self.origin
        R2 = np.einsum("ni,ni->n", v, v)
        a, b = self._a, self._b
        disc = b * b - a * (self.c @ self.c - R2)
        ok = disc >= 0.0
        s = (-b + self._sigma * np.sqrt(np.maximum(disc, 0.0))) / a
        u = self.c + self.t * s[:, None]  # (n, 3), |u| = |v| where ok
        nu = np.linalg.norm(u, axis=1)
        nv = np.linalg.norm(v, axis=1)
        v = np.where(ok[:, None], v, v * (nu / np.maximum(nv, 1e-300))[:, None])
        q1, q2, ok2 = self._subproblem2(u, v)
        return InverseResult(np.column_stack([q1, q2, s + self.q_alpha]), ok & ok2)

    def _subproblem2(self, u, v):
        """R(w1, q1) R(w2, q2) u = v (Paden-Kahan 2), the root nearest p_ref."""
        w1, w2 = self.w1, self.w2
        w12 = w1 @ w2
        den = w12 * w12 - 1.0
        al = (w12 * (u @ w2) - v @ w1) / den
        be = (w12 * (v @ w1) - u @ w2) / den
        x = np.cross(w1, w2)
        g2 = (np.einsum("ni,ni->n", u, u) - al**2 - be**2 - 2 * al * be * w12) / (x @ x)
        ok = g2 > 1e-12 * np.maximum(np.einsum("ni,ni->n", v, v), 1e-300)
        g = np.sqrt(np.maximum(g2, 0.0))
        best = None
        for sign in (1.0, -1.0):
            z = al[:, None] * w1 + be[:, None] * w2 + (sign * g)[:, None] * x
            q2 = _wrap_near(_subproblem1(w2, u, z), self.p_ref[1])
            q1 = _wrap_near(_subproblem1(w1, z, v), self.p_ref[0])
            q1 = np.where(ok, q1, self.p_ref[0])  # on the J1 axis: q1 undetermined
            if not np.all(ok):  # re-solve q2 with that q1
                zz = np.einsum("nij,nj->ni", _rot(self.K1, -q1), v)
                q2 = np.where(ok, q2, _wrap_near(_subproblem1(w2, u, zz), self.p_ref[1]))
            dist = (q1 - self.p_ref[0]) ** 2 + (q2 - self.p_ref[1]) ** 2
            if best is None:
                best = (q1, q2, dist)
            else:
                take = dist < best[2]
                best = (np.where(take, q1, best[0]), np.where(take, q2, best[1]), None)
        return best[0], best[1], ok

    # --- one sample in Python floats (the 1 kHz loop): the formulas above, per component ------
    def inverse_one(self, r) -> tuple[tuple, bool]:
        """:meth:`inverse` of one point r (3,): (q1, q2, q4) and in_domain."""
        O, w1, w2, c, t = self._f
        v = (r[0] - O[0], r[1] - O[1], r[2] - O[2])
        R2 = _dot3(v, v)
        a, b = self._a, self._b
        disc = b * b - a * (_dot3(c, c) - R2)
        ok = disc >= 0.0
        s = (-b + self._sigma * math.sqrt(max(disc, 0.0))) / a
        u = (c[0] + t[0] * s, c[1] + t[1] * s, c[2] + t[2] * s)
        if not ok:
            k = math.sqrt(_dot3(u, u)) / max(math.sqrt(R2), 1e-300)
            v = (v[0] * k, v[1] * k, v[2] * k)
        # Paden-Kahan 2 as in _subproblem2
        w12 = _dot3(w1, w2)
        den = w12 * w12 - 1.0
        uw2, vw1 = _dot3(u, w2), _dot3(v, w1)
        al = (w12 * uw2 - vw1) / den
        be = (w12 * vw1 - uw2) / den
        x = self._x
        g2 = (_dot3(u, u) - al**2 - be**2 - 2 * al * be * w12) / _dot3(x, x)
        ok2 = g2 > 1e-12 * max(_dot3(v, v), 1e-300)
        g = math.sqrt(max(g2, 0.0))
        ref0, ref1 = self.p_ref.tolist()
        best = None
        for sign in (1.0, -1.0):
            sg = sign * g
            z = (
                al * w1[0] + be * w2[0] + sg * x[0],
                al * w1[1] + be * w2[1] + sg * x[1],
                al * w1[2] + be * w2[2] + sg * x[2],
            )
            q2 = _wrap_near_f(_subproblem1_f(w2, u, z), ref1)
            q1 = _wrap_near_f(_subproblem1_f(w1, z, v), ref0)
            if not ok2:  # on the J1 axis: q1 undetermined, q2 re-solved with q1 = ref0
                q1 = ref0
                zz = _rot_f(w1, -q1, v)
                q2 = _wrap_near_f(_subproblem1_f(w2, u, zz), ref1)
            dist = (q1 - ref0) ** 2 + (q2 - ref1) ** 2
            if best is None or dist < best[2]:
                best = (q1, q2, dist)
        assert best is not None  # the loop runs at least once
        return (best[0], best[1], s + self.q_alpha), bool(ok and ok2)

    def derivatives_one(self, p) -> tuple[tuple, tuple, tuple]:
        """:meth:`derivatives` of one p: the Jacobian's columns (d1, d2, d3) and the Hessian's
        non-zero blocks (H00, H01, H02, H11, H12), each a 3-tuple (H22 = 0: l_c is linear in s)."""
        _, w1, w2, c, t = self._f
        s = p[2] - self.q_alpha
        w = (c[0] + t[0] * s, c[1] + t[1] * s, c[2] + t[2] * s)
        c1, s1, c2, s2 = math.cos(p[0]), math.sin(p[0]), math.cos(p[1]), math.sin(p[1])
        R2w, R2t = _rot_cs(w2, c2, s2, w), _rot_cs(w2, c2, s2, t)
        K2R2w, K2R2t = _cross3(w2, R2w), _cross3(w2, R2t)
        v = _rot_cs(w1, c1, s1, R2w)
        d1 = _cross3(w1, v)
        d2 = _rot_cs(w1, c1, s1, K2R2w)
        d3 = _rot_cs(w1, c1, s1, R2t)
        H = (
            _cross3(w1, d1),
            _cross3(w1, d2),
            _cross3(w1, d3),
            _rot_cs(w1, c1, s1, _cross3(w2, K2R2w)),
            _rot_cs(w1, c1, s1, K2R2t),
        )
        return (d1, d2, d3), H, v


def _dot3(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross3(a, b) -> tuple:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _rot_cs(w, c, s, x) -> tuple:
    """Rodrigues R(w, theta) x = x + sin (w x x) + (1 - cos) w x (w x x), given cos and sin."""
    k = _cross3(w, x)
    kk = _cross3(w, k)
    o = 1.0 - c
    return (x[0] + s * k[0] + o * kk[0], x[1] + s * k[1] + o * kk[1], x[2] + s * k[2] + o * kk[2])


def _rot_f(w, theta, x) -> tuple:
    return _rot_cs(w, math.cos(theta), math.sin(theta), x)


def _wrap_near_f(x: float, ref: float) -> float:
    return ref + (x - ref + math.pi) % (2.0 * math.pi) - math.pi


def _subproblem1_f(w, u, v) -> float:
    """_subproblem1 for one pair of 3-tuples."""
    uw, vw = _dot3(u, w), _dot3(v, w)
    up = (u[0] - uw * w[0], u[1] - uw * w[1], u[2] - uw * w[2])
    vp = (v[0] - vw * w[0], v[1] - vw * w[1], v[2] - vw * w[2])
    return math.atan2(_dot3(_cross3(up, vp), w), _dot3(up, vp))


def _solve3(cols, b) -> tuple:
    """x with [c0 c1 c2] x = b (Cramer: rows of the inverse are c1 x c2, c2 x c0, c0 x c1)."""
    c0, c1, c2 = cols
    r0, r1, r2 = _cross3(c1, c2), _cross3(c2, c0), _cross3(c0, c1)
    det = _dot3(c0, r0)
    if det == 0.0:
        raise np.linalg.LinAlgError("Singular matrix")  # as np.linalg.solve
    return (_dot3(r0, b) / det, _dot3(r1, b) / det, _dot3(r2, b) / det)


def _subproblem1(w, u, v):
    """theta with R(w, theta) u' = v' (projections on the plane normal to w), batched."""
    up = u - np.outer(u @ w, w)
    vp = v - np.outer(v @ w, w)
    return np.arctan2(np.cross(up, vp) @ w, np.einsum("ni,ni->n", up, vp))


class PolynomialB:
    """b(q) of eq. 12 for m_q = 3 active joints, selected joint index ``i`` (q4, index 2).

    b(p) = sum_j alpha_j p1^j1 p2^j2 (p3 - q_alpha)^(j3 + 2), j1 + j2 + j3 <= N - 2, alpha_j in R^3.
    alpha is stored as A with shape (n_mono, 3); the vector of eqs. 13-14 is A.ravel() (row-major:
    alpha = [alpha_j0 (3), alpha_j1 (3), ...]). Every monomial carries (q4 - q_alpha)^2 at least,
    so b and db/dq vanish at q4 = q_alpha (the terminal constraint, eq. 8).
    """

    def __init__(
        self, order: int = 4, q_alpha: float = math.pi / 2, n_joints: int = 3, selected: int = 2
    ) -> None:
        if order < 2:
            raise ValueError("eq. 12 needs N >= 2")
        self.order, self.q_alpha, self.m, self.i = order, float(q_alpha), n_joints, selected
        exps = [
            e
            for deg in range(order - 1)
            for e in sorted(itertools.product(range(deg + 1), repeat=n_joints), reverse=True)
            if sum(e) == deg
        ]
        self.exponents = np.array(exps, dtype=int)  # j (without the +2)
        self.powers = self.exponents.copy()
        self.powers[:, selected] += 2  # actual powers of eq. 12
        self.n_mono = len(exps)
        self.n_alpha = self.n_mono * n_joints
        # coefficients_one's per monomial: the powers (a, b, c) and the indices of x^(e-1) and
        # x^(e-2) per variable, then the factors e and e (e - 1): a factor 0.0 with index 0
        # (x^0 = 1.0) where the derivative vanishes gives 0.0, as the branch it replaces
        self._powers_t = tuple(
            (
                (a, b, c, *(max(e - 1, 0) for e in (a, b, c)), *(max(e - 2, 0) for e in (a, b, c))),
                (*(float(e) for e in (a, b, c)), *(float(e * (e - 1)) for e in (a, b, c))),
            )
            for a, b, c in (tuple(int(e) for e in row) for row in self.powers)
        )
        self._top = int(self.powers.max())

    def _vars(self, p):
        x = np.atleast_2d(np.asarray(p, float)).copy()
        x[:, self.i] -= self.q_alpha
        return x

    def monomials(self, p, derivs: int = 0):
        """m (n, nm); with derivs >= 1 also dm (n, nm, 3); with 2 also d2m (n, nm, 3, 3)."""
        x = self._vars(p)
        P = self.powers
        pw = lambda k: x[:, None, :] ** np.maximum(P - k, 0)[None]  # noqa: E731
        x0 = pw(0)
        m = x0.prod(axis=2)
        if derivs == 0:
            return m
        x1 = pw(1)
        n, nm, d = x.shape[0], self.n_mono, self.m
        dm = np.empty((n, nm, d))
        for k in range(d):
            f = x0.copy()
            f[:, :, k] = P[None, :, k] * x1[:, :, k]
            dm[:, :, k] = f.prod(axis=2)
        if derivs == 1:
            return m, dm
        x2 = pw(2)
        d2m = np.empty((n, nm, d, d))
        for k in range(d):
            for l in range(k, d):
                f = x0.copy()
                if k == l:
                    f[:, :, k] = (P[None, :, k] * (P[None, :, k] - 1)) * x2[:, :, k]
                else:
                    f[:, :, k] = P[None, :, k] * x1[:, :, k]
                    f[:, :, l] = P[None, :, l] * x1[:, :, l]
                d2m[:, :, k, l] = d2m[:, :, l, k] = f.prod(axis=2)
        return m, dm, d2m

    def coefficients_one(self, p, pd, pdd) -> tuple[list, list, list]:
        """For one sample of the 3 active joints: per monomial m_j, dm_j . pd and
        dm_j . pdd + pd^T d2m_j pd (the rows of m, m1, m2 in :class:`Features`), from the
        powers of x = (p1, p2, p4 - q_alpha), each derivative written out per variable."""
        if self.m != 3:
            raise ValueError("coefficients_one is written for 3 active joints")
        x = list(p)
        x[self.i] -= self.q_alpha
        top = self._top
        X, Y, Z = ([1.0] * (top + 1) for _ in range(3))  # X[e] = x_0^e, ...
        for e in range(1, top + 1):
            X[e], Y[e], Z[e] = X[e - 1] * x[0], Y[e - 1] * x[1], Z[e - 1] * x[2]
        u0, u1, u2 = pd
        v0, v1, v2 = pdd
        m, m1, m2 = [], [], []
        for (a, b, c, ia, ib, ic, ja, jb, jc), (ka, kb, kc, la, lb, lc) in self._powers_t:
            fa, fb, fc = X[a], Y[b], Z[c]
            ga, gb, gc = ka * X[ia], kb * Y[ib], kc * Z[ic]  # d x^e / dx = e x^(e-1)
            ha, hb, hc = la * X[ja], lb * Y[jb], lc * Z[jc]  # e (e-1) x^(e-2)
            d0, d1, d2 = ga * fb * fc, fa * gb * fc, fa * fb * gc
            quad = (
                ha * fb * fc * u0 * u0
                + fa * hb * fc * u1 * u1
                + fa * fb * hc * u2 * u2
                + 2.0 * (ga * gb * fc * u0 * u1 + ga * fb * gc * u0 * u2 + fa * gb * gc * u1 * u2)
            )
            m.append(fa * fb * fc)
            m1.append(d0 * u0 + d1 * u1 + d2 * u2)
            m2.append(d0 * v0 + d1 * v1 + d2 * v2 + quad)
        return m, m1, m2

    def value(self, p, A) -> np.ndarray:
        return self.monomials(p) @ np.asarray(A).reshape(self.n_mono, self.m)

    def jacobian(self, p, A) -> np.ndarray:
        """db/dp, (n, 3, 3)."""
        _, dm = self.monomials(p, 1)
        return np.einsum("njk,ji->nik", dm, np.asarray(A).reshape(self.n_mono, self.m))

    def design(self, m_row: np.ndarray) -> np.ndarray:
        """d(m @ A)/d alpha for a monomial-like row (nm,): kron(m, I) (3, n_alpha) (eq. 14)."""
        return np.kron(m_row[None, :], np.eye(self.m))


@dataclass
class Features:
    """Everything about a set of object states that does not depend on alpha.

    q_d = p + m A,  qd_d = pd + m1 A,  qdd_d = pdd + m2 A  (eqs. 7, 8, 12, 16, 23).
    """

    p: np.ndarray  # (n, 3) q_o = l_c^-1(r_o)
    pd: np.ndarray  # (n, 3) d q_o / dt = J_c^-1 r_o'
    pdd: np.ndarray  # (n, 3)
    m: np.ndarray  # (n, nm)
    m1: np.ndarray  # (n, nm)  dm . pd
    m2: np.ndarray  # (n, nm)  dm . pdd + d2m[pd, pd]
    dm: np.ndarray  # (n, nm, 3)
    Jc: np.ndarray  # (n, 3, 3)
    in_domain: np.ndarray


class DirectMapping:
    """f(r_o) = g o l_c^-1(r_o) (eq. 7) with parameters A of b (eq. 12)."""

    def __init__(self, geometry: CatchGeometry, poly: PolynomialB, alpha=None) -> None:
        self.geo, self.poly = geometry, poly
        self.A = np.zeros(poly.n_alpha) if alpha is None else alpha

    @property
    def A(self) -> np.ndarray:
        """alpha as an (n_mono, m_q) array (a copy is stored on assignment)."""
        return self._A

    @A.setter
    def A(self, value) -> None:
        self._A = np.array(value, dtype=float).reshape(self.poly.n_mono, self.poly.m)

    @property
    def alpha(self) -> np.ndarray:
        return self._A.ravel().copy()

    def features(self, r, rd=None, rdd=None) -> Features:
        r = np.atleast_2d(np.asarray(r, float))
        n = len(r)
        rd = np.zeros((n, 3)) if rd is None else np.atleast_2d(np.asarray(rd, float))
        rdd = np.zeros((n, 3)) if rdd is None else np.atleast_2d(np.asarray(rdd, float))
        inv = self.geo.inverse(r)
        p = inv.p
        _, J, H = self.geo.derivatives(p)
        pd = np.linalg.solve(J, rd[..., None])[..., 0]
        pdd = np.linalg.solve(J, (rdd - np.einsum("nikl,nk,nl->ni", H, pd, pd))[..., None])[..., 0]
        m, dm, d2m = self.poly.monomials(p, 2)
        m1 = np.einsum("njk,nk->nj", dm, pd)
        m2 = np.einsum("njk,nk->nj", dm, pdd) + np.einsum("njkl,nk,nl->nj", d2m, pd, pd)
        return Features(p, pd, pdd, m, m1, m2, dm, J, inv.in_domain)

    def evaluate(self, r, rd=None, rdd=None, A=None):
        """(q_d, qd_d, qdd_d, features): the desired active joint trajectory and derivatives."""
        A = self.A if A is None else np.asarray(A).reshape(self.poly.n_mono, self.poly.m)
        f = self.features(r, rd, rdd)
        return f.p + f.m @ A, f.pd + f.m1 @ A, f.pdd + f.m2 @ A, f

    def evaluate_one(self, r, rd, rdd):
        """:meth:`evaluate` of one object state (r_o, r_o', r_o'' each (3,)): (q_d, qd_d,
        qdd_d, q_o, in_domain), arrays (3,) but in_domain (a test holds it to the batched
        :meth:`evaluate`)."""
        q, qd, qdd, p, ok = self.evaluate_one_tuple(r, rd, rdd)
        return np.array(q), np.array(qd), np.array(qdd), np.array(p), ok

    def evaluate_one_tuple(self, r, rd, rdd) -> tuple[tuple, tuple, tuple, tuple, bool]:
        """:meth:`evaluate_one` with 3-tuples of floats, in Python floats (the controller's
        per-step path): the closed-form inverse, J_c^-1 r_o' and J_c^-1 (r_o'' - H(r_o', r_o'))
        by Cramer's rule, then b(q) and its derivatives (eq. 12) from the monomials."""
        if self.poly.m != 3 or self.poly.i != 2:
            raise ValueError("evaluate_one is written for 3 active joints, the last selected")
        r, rd, rdd = list(map(float, r)), list(map(float, rd)), list(map(float, rdd))
        p, ok = self.geo.inverse_one(r)
        J, H, _ = self.geo.derivatives_one(p)
        pd = _solve3(J, rd)
        a, b, c = pd
        H00, H01, H02, H11, H12 = H
        aa, ab2, ac2, bb, bc2 = a * a, 2 * a * b, 2 * a * c, b * b, 2 * b * c
        # r_o'' - H(pd, pd), per component written out (no comprehension a step)
        h = [
            rdd[0] - (H00[0] * aa + H01[0] * ab2 + H02[0] * ac2 + H11[0] * bb + H12[0] * bc2),
            rdd[1] - (H00[1] * aa + H01[1] * ab2 + H02[1] * ac2 + H11[1] * bb + H12[1] * bc2),
            rdd[2] - (H00[2] * aa + H01[2] * ab2 + H02[2] * ac2 + H11[2] * bb + H12[2] * bc2),
        ]
        pdd = _solve3(J, h)
        out = np.array((p, pd, pdd)) + np.array(self.poly.coefficients_one(p, pd, pdd)) @ self._A
        q, qd, qdd = out.tolist()
        return tuple(q), tuple(qd), tuple(qdd), tuple(p), ok

    def __call__(self, r) -> np.ndarray:
        """q_d = f(r_o) (active joints)."""
        f = self.features(r)
        return f.p + f.m @ self.A

    def F(self, r) -> np.ndarray:
        """F = df/dr_o = (I + db/dq) J_c^-1 (eq. 16), (n, 3, 3)."""
        f = self.features(r)
        G = np.eye(3) + np.einsum("njk,ji->nik", f.dm, self.A)
        return G @ np.linalg.inv(f.Jc)

    def constraint(self, r0, rd0, p_start, pd_start=(0.0, 0.0, 0.0)):
        """C and the right-hand side of eq. 13 for the initial object state (r0, rd0).

        C = [db/dalpha; d(db/dt)/dalpha] at t0 (eq. 14): rows kron(m(q_o), I) and
        kron(dm . qd_o, I); rhs = [q(t0) - q_o(t0); qd(t0) - qd_o(t0)].
        """
        f = self.features(np.atleast_2d(r0), np.atleast_2d(rd0))
        C = np.vstack([self.poly.design(f.m[0]), self.poly.design(f.m1[0])])
        rhs = np.concatenate(
            [np.asarray(p_start, float) - f.p[0], np.asarray(pd_start, float) - f.pd[0]]
        )
        return C, rhs
