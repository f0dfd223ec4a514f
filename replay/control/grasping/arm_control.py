"""Tracking and reaching control of the arm (Namiki et al. 1999, Sec. 4.2, eqs. 2-3):

    theta_dot_d^a = K^ap J^a+ S K^a1 (x^o - x^a) + K^ap J^a+ (I - S) K^a2 (x_d^a - x^a)
                    - K^av theta_dot^a + K^af J^aT F^a                                 (2)
    S = diag(s_i),  s_i = 1 for i = y, z, roll, else 0                                (3)

- x = (x, y, z, roll, pitch, yaw) in the world; the constraint plane's normal is world x, so
  tracking (S) acts in the plane (y, z) and about its normal (roll), reaching (I - S) along the
  normal (x) and on pitch/yaw (the palm kept facing the plane). Orientation errors are rotation
  vectors (world): roll = the angle from the palm's finger-row axis to the object's long axis
  about the plane normal (modulo pi; zero for a circle, which has none), pitch/yaw = n_palm x
  n_plane. x^a is the hand's grasp point (``grasp_point`` ahead of the palm's back face) from
  the joint encoders through the arm's nominal kinematics.
- The paper's arm has 6 joints in eq. 2 (J^a 6 x 6); the WAM-7 has 7: **all 7 are used with a
  damped pseudo-inverse** J+ = J^T (J J^T + lambda^2 I)^-1 (the minimum-norm joint rates; no
  joint is locked).
- F^a: the wrist sensor's wrench turned into the world, minus the hand's own weight (nominal
  mass and centre of mass, open posture) and the sensor's bias at start (tare), about the
  flange: the external wrench on the hand (N, N m).
- No prediction of the object's motion: x^o is the latest measurement.
- Per step: the chain and Jg (:meth:`ArmControlTask._chain`, floats; held by the tests to the
  chain's matrix products), eq. 2's terms (:func:`eq2_terms`) and F^a (:func:`wrench_step`,
  floats); eq. 2 written out in NumPy, the formula a seeded test holds the task's command to, is
  the tests' oracle (tests/replay/control/grasping/oracles.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from replay.control.grasping.gain_rule import check_period, direct_gains, scale
from replay.control.grasping.payloads import ArmLoop
from replay.interfaces import Controller
from replay.messages import (
    TOPIC_ARM_ENCODERS,
    TOPIC_GRASP_ARM,
    TOPIC_GRASP_OBJECT,
    TOPIC_GRASP_STATE,
    TOPIC_WRIST_WRENCH,
)
from replay.params import param
from replay.robot.arm_types import GraspSpec, ServoCommand
from replay.robot.hand import hand_body
from replay.spatial import wrap_half_pi

S_DIAG = np.array([0.0, 1.0, 1.0, 1.0, 0.0, 0.0])  # eq. 3
# 1/s: the wrist force loop's rate at 1 ms, K^af r^2 k_h (0.3 rad/(s N m), ~0.6 m from the
# shoulder, the human's 500 N/m), the direct loop K^af shares its gain factor with (gain_rule.py)
FORCE_LOOP_RATE = 54.0


def eq2_terms(Jg, J, n, lam2, b1, b2, qd, F, K_ap, K_av, K_af, vlim) -> tuple[list, ...]:
    """Eq. 2's joint-velocity terms (track, reach, damp, force, command): track = K_ap Jg+ b1,
    reach = K_ap Jg+ b2 with the damped pseudo-inverse Jg+ = Jg^T (Jg Jg^T + lam2 I)^-1 (b1 =
    S K^a1 e_track, b2 = (I - S) K^a2 e_reach), damp = -K_av qd, force = K_af J^T F; command =
    their sum clipped to +-vlim."""
    A = Jg @ Jg.T + lam2 * np.eye(6)
    y = np.linalg.solve(A, np.array([b1, b2], float).T)
    tr = K_ap * (Jg.T @ y)
    damp = -K_av * np.asarray(qd, float)
    force = K_af * (J.T @ np.asarray(F, float))
    cmd = np.clip(tr[:, 0] + tr[:, 1] + damp + force, -np.asarray(vlim), np.asarray(vlim))
    return tr[:, 0].tolist(), tr[:, 1].tolist(), damp.tolist(), force.tolist(), cmd.tolist()


def wrench_step(R, force, torque, w_hand, com, bias, filtered, a, deadband):
    """(ext, filtered, F): the wrist sensor's wrench turned into the world (R: the tool's
    rotation, row-major 9 floats) minus the hand's weight ``w_hand`` acting at R com, ext = (R f
    - w, R m - (R com) x w); ``bias`` None: this ext is the tare (the filter restarts at 0);
    filtered += a ((ext - bias) - filtered); F = filtered, or 0 while its force is below the
    deadband."""
    r = [R[3 * i] * com[0] + R[3 * i + 1] * com[1] + R[3 * i + 2] * com[2] for i in range(3)]
    w = w_hand
    rxw = (r[1] * w[2] - r[2] * w[1], r[2] * w[0] - r[0] * w[2], r[0] * w[1] - r[1] * w[0])
    ext = [
        R[3 * i] * force[0] + R[3 * i + 1] * force[1] + R[3 * i + 2] * force[2] - w[i]
        for i in range(3)
    ]
    ext += [
        R[3 * i] * torque[0] + R[3 * i + 1] * torque[1] + R[3 * i + 2] * torque[2] - rxw[i]
        for i in range(3)
    ]
    if bias is None:
        bias, filtered = ext, [0.0] * 6
    fl = [f + a * (e - b - f) for f, e, b in zip(filtered, ext, bias)]
    quiet = math.sqrt(fl[0] * fl[0] + fl[1] * fl[1] + fl[2] * fl[2]) < deadband
    return ext, fl, ([0.0] * 6 if quiet else list(fl))


@dataclass
class ArmParams:
    K_ap: float = param(1.0, unit="1", ge=0.0, doc="eq. 2's K^ap (a scalar times I)")
    K_a1: list = param(
        [0.0, 60.0, 60.0, 30.0, 0.0, 0.0],
        unit="1/s",
        length=6,
        ge=0.0,
        doc="eq. 2's K^a1 (tracking; only the S components act; assumed)",
    )
    K_a2: list = param(
        [60.0, 0.0, 0.0, 0.0, 20.0, 20.0],
        unit="1/s",
        length=6,
        ge=0.0,
        doc="eq. 2's K^a2 (reaching; only the I - S components act; assumed)",
    )
    reach_tracking: float = param(
        1.0,
        unit="1",
        ge=0.0,
        le=1.0,
        doc="the share of eq. 2's tracking term S K^a1 (x^o - x^a) kept while reaching: 1 is "
        "eq. 3's partition, tracking and reaching at once; 0 a sequential look-then-move "
        "controller that stops tracking to reach (a falsifier of eq. 3's row)",
    )
    K_av: float = param(0.05, unit="1", ge=0.0, doc="eq. 2's K^av (scalar times I)")
    K_af: float = param(
        0.3,
        unit="rad/(s*N*m)",
        ge=0.0,
        doc="eq. 2's K^af (scalar times I): compliance to the external wrench on the hand "
        "(assumed; the ablation analysis/grasping/ablations.py compares 0, 0.3 and 0.6)",
    )
    grasp_point: float = param(
        0.045,
        unit="m",
        ge=0.0,
        doc="x^a: the hand's grasp point this far along the palm normal "
        "from its back face (between the fingers)",
    )
    damping: float = param(0.01, unit="m", gt=0.0, doc="lambda of the damped pseudo-inverse")
    force_deadband: float = param(
        1.0,
        unit="N",
        ge=0.0,
        doc="external forces below this are taken as zero (sensor noise and the hand's inertia)",
    )
    hold_offset_filter: float = param(
        0.0,
        unit="s",
        ge=0.0,
        doc="hold: eq. 2's errors (x^o - x^a on S, x_d^a - x^a on I - S) are taken from where "
        "the object sat in the hand when the hold began, that offset following them with this "
        "time constant (0: latched): the arm keeps the grasp instead of chasing a ball that "
        "sits off the grasp point (assumed)",
    )
    force_filter: float = param(
        0.01,
        unit="s",
        ge=0.0,
        doc="time constant of the first-order low-pass on F^a: the "
        "wrist also feels the hand's inertia (m a), and feeding that "
        "back through the 1 ms loop unfiltered is unstable",
    )
    gain_period: float = param(
        0.0,
        unit="s",
        ge=0.0,
        omit_empty=True,
        doc="the gain rule: 0 keeps K^a1, K^a2, K^af as given (tuned for 1 ms loops); a period T "
        "(s, the task's 1 / rate) re-designs each for it, the 1 ms loop's pole kept "
        "(gain_rule.direct_gain; K^af scaled as a loop of FORCE_LOOP_RATE)",
    )


class ArmControlTask(Controller):
    """Eqs. 2-3: arm tracking (S) and reaching (I - S) with wrist force feedback."""

    Params = ArmParams
    spec_type = GraspSpec
    command_type = ServoCommand
    reads = (TOPIC_ARM_ENCODERS, TOPIC_WRIST_WRENCH, TOPIC_GRASP_OBJECT, TOPIC_GRASP_STATE)
    description = "eqs. 2-3: arm tracking (S) and reaching (I - S) with wrist force feedback"

    def __init__(self, params: ArmParams, *, spec: GraspSpec) -> None:
        super().__init__(params, spec=spec)
        self.chain = spec.model
        # the chain as floats for the per-step products (cos alpha, sin alpha, a, d, theta
        # offset per joint; base and tool as their top 3 rows), the Jacobians a step fills (tool,
        # grasp point; J also as rows of floats) and eq. 2's gains on the task vectors
        n = self._n = len(self.chain.dh)
        self._dh_f = [
            (
                float(np.cos(r.alpha)),
                float(np.sin(r.alpha)),
                float(r.a),
                float(r.d),
                float(r.theta_offset),
            )
            for r in self.chain.dh
        ]
        self._base_f = np.asarray(self.chain.base, float)[:3].ravel().tolist()
        self._tool_f = np.asarray(self.chain.tool, float)[:3].ravel().tolist()
        self._J, self._Jg = np.zeros((6, n)), np.zeros((6, n))
        self._J_rows: list[list[float]] = [[0.0] * n for _ in range(6)]
        if spec.plane is None or spec.hand is None:
            raise ValueError("arm control needs a plant with a hand and a constraint plane")
        self.n_plane = np.asarray(spec.plane.normal, float)
        self._n_plane = [float(x) for x in self.n_plane]
        self.hand = hand_body(spec.hand.table)
        self.g = np.array([0.0, 0.0, -spec.gravity])
        self._g = self.g.tolist()
        self._com = [float(x) for x in self.hand.com]
        self.vlim = np.asarray(spec.velocity_limits, float)
        self._vlim = self.vlim.tolist()
        self.dt = spec.dt  # the task's period (from its update times)
        self._t_last: float | None = None
        T = params.gain_period  # the gain rule (gain_rule.py): 0 keeps the gains
        self.K_a1 = np.asarray(direct_gains(params.K_a1, T), float)
        self.K_a2 = np.asarray(direct_gains(params.K_a2, T), float)
        self.K_af = params.K_af * scale(FORCE_LOOP_RATE, T)
        self._g_track = (S_DIAG * self.K_a1).tolist()  # eq. 2's S K^a1 and (I - S) K^a2
        self._g_reach = ((1.0 - S_DIAG) * self.K_a2).tolist()
        self._g_track_reach = [params.reach_tracking * g for g in self._g_track]
        self.q: list[float] = [float(x) for x in spec.initial_q]
        self.qd = [0.0] * len(self.q)
        self.obj: Any = None
        self.state: Any = None
        self.wrench_raw: Any = None
        # the sensor's offset: the simulated sensor has none (replay/sensors/force.py: noise
        # only), and a tare at the first reading took in the hand's start-up transient
        self.bias: list[float] | None = [0.0] * 6
        self.filtered = [0.0] * 6
        self._v_com: list[float] | None = None  # the hand's centre of mass velocity (world)
        self._enc_t: float | None = None  # the newest encoder reading's time, and the one before's
        self._enc_prev: tuple[float | None, list[float]] = (None, self.qd)
        self._hold: tuple | None = None  # (cycle, offset on x^o - x^a, offset on x_d - x^a)
        self._out: ArmLoop | None = None
        self.track_sq: dict[str, list] = {}

    def _chain(self, grasp_point: float) -> tuple[float, ...]:
        """(R row-major, p, grasp point g = p + grasp_point R[:, 2]) of the tool at ``self.q``;
        sets ``self._J`` (the tool's geometric Jacobian, rows vx vy vz wx wy wz) and
        ``self._Jg`` (the grasp point's: v_g = v + w x (g - p)). The chain's transforms in floats (3 x 4
        rigid transforms as 12 floats), held by a seeded test to SerialChain.fk and .jacobian."""
        T = self._base_f
        Z, O = [], []
        for (ca, sa, a, d, off), q in zip(self._dh_f, self.q):
            th = q + off
            ct, st = math.cos(th), math.sin(th)
            Z.append((T[2], T[6], T[10]))
            O.append((T[3], T[7], T[11]))
            m01, m02, m03 = -st * ca, st * sa, a * ct  # dh_transform's rows 0 and 1 (row 2:
            m11, m12, m13 = ct * ca, -ct * sa, a * st  # 0, sa, ca, d)
            T = [
                x
                for r in (0, 4, 8)
                for x in (
                    T[r] * ct + T[r + 1] * st,
                    T[r] * m01 + T[r + 1] * m11 + T[r + 2] * sa,
                    T[r] * m02 + T[r + 1] * m12 + T[r + 2] * ca,
                    T[r] * m03 + T[r + 1] * m13 + T[r + 2] * d + T[r + 3],
                )
            ]
        B = self._tool_f
        T = [
            T[r] * B[c] + T[r + 1] * B[4 + c] + T[r + 2] * B[8 + c] + (T[r + 3] if c == 3 else 0.0)
            for r in (0, 4, 8)
            for c in range(4)
        ]
        px, py, pz = T[3], T[7], T[11]
        rx, ry, rz = grasp_point * T[2], grasp_point * T[6], grasp_point * T[10]  # g - p
        vx, vy, vz = [], [], []
        for (zx, zy, zz), (ox, oy, oz) in zip(Z, O):
            dx, dy, dz = px - ox, py - oy, pz - oz
            vx.append(zy * dz - zz * dy)
            vy.append(zz * dx - zx * dz)
            vz.append(zx * dy - zy * dx)
        wx, wy, wz = (list(c) for c in zip(*Z))
        self._J_rows = [vx, vy, vz, wx, wy, wz]
        self._J = np.array(self._J_rows)
        self._Jg = np.array(
            [
                [v - (ry * c - rz * b) for v, b, c in zip(vx, wy, wz)],
                [v - (rz * a - rx * c) for v, a, c in zip(vy, wx, wz)],
                [v - (rx * b - ry * a) for v, a, b in zip(vz, wx, wy)],
                wx,
                wy,
                wz,
            ]
        )
        R = (T[0], T[1], T[2], T[4], T[5], T[6], T[8], T[9], T[10])
        return (*R, px, py, pz, px + rx, py + ry, pz + rz)

    def hand_acceleration(self, R) -> list[float]:
        """The hand's centre-of-mass acceleration (world, m/s^2) from the arm's kinematics:
        v_com = v_tool + w x (R com) with (v_tool, w) = J theta_dot (the tool Jacobian of this
        step's chain), differenced over the task's period."""
        c = self._com
        r = [R[3 * i] * c[0] + R[3 * i + 1] * c[1] + R[3 * i + 2] * c[2] for i in range(3)]
        v = self._com_velocity(self.qd, r)
        t0, qd0 = self._enc_prev
        if self.params.gain_period > 0.0 and t0 is not None and self._enc_t is not None:
            # the discrete rule: the newest two encoder readings (1 ms apart, this step's chain),
            # the acceleration at the wrist sensor's instant; over a long period the difference
            # of the task's own steps lags it and feeds m dv / T back as a force
            dt = self._enc_t - t0
            v0 = self._com_velocity(qd0, r)
            return [(a - b) / dt for a, b in zip(v, v0)] if dt > 0.0 else [0.0, 0.0, 0.0]
        prev, self._v_com = self._v_com, v
        if prev is None or self.dt <= 0.0:
            return [0.0, 0.0, 0.0]
        return [(a - b) / self.dt for a, b in zip(v, prev)]

    def _com_velocity(self, qd, r) -> list[float]:
        """The hand's centre-of-mass velocity v_tool + w x r (world) at joint rates ``qd``, ``r``
        the centre of mass from the tool origin (world), by this step's tool Jacobian."""
        tw = [sum(a * b for a, b in zip(row, qd)) for row in self._J_rows]
        wx, wy, wz = tw[3], tw[4], tw[5]
        return [
            tw[0] + wy * r[2] - wz * r[1],
            tw[1] + wz * r[0] - wx * r[2],
            tw[2] + wx * r[1] - wy * r[0],
        ]

    def external_wrench(self, R) -> list[float]:
        """F^a (world, about the flange): the sensor's wrench minus the hand's gravity and
        inertial load m (g - a_com) (the sensor reads m g - m a + F_ext; a_com from the arm's
        kinematics: :meth:`hand_acceleration`), low-passed, zero within the deadband (:func:`wrench_step`). ``R``: the tool's rotation, row-major
        9 floats."""
        a = self.dt / (self.params.force_filter + self.dt)
        acc = self.hand_acceleration(R)
        m = self.hand.mass
        load = [m * (g - x) for g, x in zip(self._g, acc)]
        ext, self.filtered, F = wrench_step(
            R,
            self.wrench_raw.force,
            self.wrench_raw.torque,
            load,
            self._com,
            self.bias,
            self.filtered,
            a,
            self.params.force_deadband,
        )
        return F

    def update(self, t: float, measurements) -> ServoCommand | None:
        self._read(measurements)
        if self._t_last is not None and t > self._t_last:
            self.dt = t - self._t_last
            check_period(self.params.gain_period, self.dt, "arm")
        self._t_last = t
        if self.state is None:
            return None
        P, n = self.params, self._n
        # tool pose, grasp point x^a, J (tool) and Jg (grasp point: v_gp = v_tool + w x (gp - p))
        k = self._chain(P.grasp_point)
        R = k[:9]
        gp = k[12:15]
        obj, xd = self.obj, self.state.x_d
        e_track, e_reach = self._errors(R, gp)
        self._hold_offsets(e_track, e_reach)
        F = self.external_wrench(R) if self.wrench_raw is not None else [0.0] * 6
        track, reach, damp, force, cmd = eq2_terms(
            self._Jg,
            self._J,
            n,
            P.damping**2,
            [
                g * e
                for g, e in zip(
                    self._g_track_reach if self.state.phase == "reach" else self._g_track, e_track
                )
            ],
            [g * e for g, e in zip(self._g_reach, e_reach)],
            self.qd,
            F,
            P.K_ap,
            P.K_av,
            self.K_af,
            self._vlim,
        )
        self._out = ArmLoop(
            t,
            [gp[0], gp[1], gp[2], 0.0, 0.0, 0.0],
            (obj.x_o if obj is not None else []),
            list(xd),
            [e_track[1], e_track[2], e_track[3]],
            F,
            {"track": track, "reach": reach, "damp": damp, "force": force},
            cmd,
        )
        ph = self.state.phase
        acc = self.track_sq.get(ph)
        if acc is None:
            acc = self.track_sq[ph] = [0.0, 0]
        acc[0] += e_track[1] ** 2 + e_track[2] ** 2
        acc[1] += 1
        return ServoCommand(arm=cmd)

    def _read(self, measurements) -> None:
        """Keep the latest encoders (and the previous sample's time and rates), wrench, seen
        object (when found) and schedule state."""
        for topic, m in measurements:
            if topic == TOPIC_ARM_ENCODERS:
                self._enc_prev = (self._enc_t, self.qd)
                self._enc_t = m.t
                self.q, self.qd = m.position, m.velocity
            elif topic == TOPIC_WRIST_WRENCH:
                self.wrench_raw = m
            elif topic == TOPIC_GRASP_OBJECT:
                if m.found:
                    self.obj = m
            elif topic == TOPIC_GRASP_STATE:
                self.state = m

    def _errors(self, R, gp) -> tuple[list, list]:
        """The hand's (x^a: grasp point ``gp``, tool rotation ``R`` row-major) errors to the
        object x^o and to the schedule's x_d^a, as world 6-vectors (e_track, e_reach)."""
        n_palm, row = (R[2], R[5], R[8]), (R[1], R[4], R[7])
        e_track = [0.0] * 6
        obj = self.obj
        if obj is not None:
            xo = obj.position
            e_track[0], e_track[1], e_track[2] = xo[0] - gp[0], xo[1] - gp[1], xo[2] - gp[2]
            if obj.roll is not None and obj.shape != "circle":
                e_track[3] = wrap_half_pi(obj.roll - math.atan2(row[2], row[1]))
        xd = self.state.x_d
        npl = self._n_plane
        e_reach = [
            xd[0] - gp[0],
            xd[1] - gp[1],
            xd[2] - gp[2],
            n_palm[1] * npl[2] - n_palm[2] * npl[1],
            n_palm[2] * npl[0] - n_palm[0] * npl[2],
            n_palm[0] * npl[1] - n_palm[1] * npl[0],
        ]
        return e_track, e_reach

    def _hold_offsets(self, e_track: list, e_reach: list) -> None:
        """In the hold phase the translational errors count from where the object sat in the
        hand when the hold began (the offsets then follow them with ``hold_offset_filter``):
        holding, not chasing (issue #20). Changes ``e_track``, ``e_reach`` in place."""
        st = self.state
        if st.phase != "hold" or self.obj is None:
            self._hold = None
            return
        if self._hold is None or self._hold[0] != st.cycle:
            self._hold = (st.cycle, e_track[:3], e_reach[:3])
        _, dt_, dr_ = self._hold
        tau = self.params.hold_offset_filter
        b = self.dt / (tau + self.dt) if tau > 0.0 else 0.0
        for i in range(3):
            dt_[i] += b * (e_track[i] - dt_[i])
            dr_[i] += b * (e_reach[i] - dr_[i])
            e_track[i] -= dt_[i]
            e_reach[i] -= dr_[i]

    def telemetry(self, t: float) -> dict:
        return {TOPIC_GRASP_ARM: self._out} if self._out is not None else {}

    def outcome(self, t: float) -> dict:
        return {
            "tracking_error_rms_by_phase": {
                ph: math.sqrt(s / n) for ph, (s, n) in sorted(self.track_sq.items()) if n
            }
        }
