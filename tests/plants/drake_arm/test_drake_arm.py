"""The Drake arm plant (plants/drake_arm) against our NumPy model (replay.robot) and the other
engines: Drake's inverse dynamics and mass matrix are our RNEA's, one step of free motion follows
the model, a thrown ball flies MuJoCo's path, the wrist reads the hanging hand's static load as
PyBullet's does, the arm servos' step response has the stated bandwidth, the grasping rig held
still stays still, and the Drake scenarios differ from their PyBullet twins only in the plant."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from grasp_rig import DT, Q0, rise_bandwidth

from plants.arm_rig.servo import VelocityServos
from plants.drake_arm import Params
from plants.drake_arm.grasp_plant import DrakeGraspPlant
from plants.drake_arm.params import GraspParams
from plants.drake_arm.plant import DrakeArmPlant
from plants.mujoco_arm import Params as MujocoParams
from plants.mujoco_arm.plant import MujocoArmPlant
from replay.robot.arm_types import ArmCommand, ServoCommand
from replay.robot.hand import GRASP4, hand_body, hand_mass
from replay.robot.serial_chain import active_block
from replay.robot.wam import wam_joint_limits

ROOT = Path(__file__).resolve().parents[3]
START = [0.0, math.pi / 4, 0.0, 0.0]  # Namiki & Ishikawa IV-A
CATCHING = dict(initial_q=START, locked_joints=["J3"])
G = np.array([0.0, 0.0, -9.81])
DK_FIELDS = {"dk_contact_approximation", "dk_point_stiffness", "dk_dissipation"}
DK_FIELDS |= {"dk_hand_servo_gain", "dk_contact_model", "dk_hydroelastic_modulus"}


def make(**kw) -> DrakeArmPlant:
    return DrakeArmPlant(Params(**kw), dt=DT, rng=np.random.default_rng(0))


def hold_torque(plant, q_ref, omega=30.0):
    """A test-side joint PD + gravity compensation from the nominal model (not the plant's)."""
    q, qd = plant.arm_state()
    model = plant.spec().model
    m = np.diag(model.mass_matrix(q))
    return model.gravity_torque(q) + m * omega**2 * (np.asarray(q_ref) - q) - 2.0 * m * omega * qd


# ---------------------------------------------------------------- dynamics vs our RNEA
def test_drake_inverse_dynamics_and_mass_matrix_equal_rnea():
    """Drake's CalcInverseDynamics and mass matrix of the arm's joints, the hand frozen (its
    joints at rest at their posture), are the nominal model's RNEA and M with the hand as a
    payload (tests/replay/robot/oracles: the RNEA's own oracle)."""
    from pydrake.multibody.tree import MultibodyForces

    plant = make(**CATCHING)
    spec, W, p, ctx = plant.spec(), plant.world, plant.mbp, plant.ctx
    a = list(spec.active)
    rng = np.random.default_rng(3)
    lo, hi = wam_joint_limits(4)
    worst = 0.0
    for _ in range(20):
        q, qd, qdd = rng.uniform(lo, hi), rng.uniform(-3, 3, 4), rng.uniform(-20, 20, 4)
        q[2] = qd[2] = qdd[2] = 0.0
        x, v = p.GetPositions(ctx), np.zeros(p.num_velocities())
        vdot = np.zeros(p.num_velocities())
        for k, i in enumerate(a):
            x[W.arm_q[k]], v[W.arm_v[k]], vdot[W.arm_v[k]] = q[i], qd[i], qdd[i]
        p.SetPositions(ctx, x)
        p.SetVelocities(ctx, v)
        gravity = MultibodyForces(p)
        p.CalcForceElementsContribution(ctx, gravity)  # Drake's gravity is a force element
        tau = p.CalcInverseDynamics(ctx, vdot, gravity)[list(W.arm_v)]
        tau_n = spec.model.rnea(q, qd, qdd)[a]
        np.testing.assert_allclose(tau, tau_n, atol=1e-9 * max(1.0, np.abs(tau_n).max()))
        M = p.CalcMassMatrix(ctx)[np.ix_(W.arm_v, W.arm_v)]
        np.testing.assert_allclose(
            M, active_block(spec.model.mass_matrix(q), spec.active), atol=1e-9
        )
        worst = max(worst, float(np.abs(tau - tau_n).max()))
    print(f"max |tau_drake - tau_rnea| over 20 states: {worst:.2e} N*m")


def test_one_step_of_free_motion_follows_the_model():
    """From rest with a torque, the velocity after one step is M^-1 (tau - g) dt."""
    plant = make(**CATCHING)
    spec = plant.spec()
    tau = np.array([5.0, -3.0, 0.0, 2.0])
    plant.apply(ArmCommand(tau))
    plant.step()
    _, qd = plant.arm_state()
    a = list(spec.active)
    q0 = np.asarray(START)
    qdd = np.linalg.solve(
        active_block(spec.model.mass_matrix(q0), spec.active),
        tau[a] - spec.model.gravity_torque(q0)[a],
    )
    np.testing.assert_allclose(qd[a], qdd * DT, rtol=1e-4, atol=1e-7)


# ---------------------------------------------------------------- ballistic ball
def test_ballistic_ball_flies_mujocos_path():
    """A thrown ball that touches nothing: Drake's path is MuJoCo's within 1e-6 m (both
    integrate by semi-implicit Euler) and the parabola within g dt t / 2 (+ rounding)."""
    r0, v0 = np.array([2.6, 0.1, 1.0]), np.array([-8.0, 0.5, 1.0])
    kw = dict(object_position=r0.tolist(), object_velocity=v0.tolist(), **CATCHING)
    paths = {}
    for name, plant in (
        ("drake", make(**kw)),
        ("mujoco", MujocoArmPlant(MujocoParams(**kw), dt=DT, rng=np.random.default_rng(0))),
    ):
        out = []
        for _ in range(150):
            plant.apply(ArmCommand(hold_torque(plant, START)))
            plant.step()
            out.append(np.concatenate(plant.object_state()[::2]))  # position, velocity
            assert not [e for e in plant.pop_events() if e.kind == "contact"]
        paths[name] = np.array(out)
    t = DT * np.arange(1, 151)[:, None]
    exact = r0 + v0 * t + 0.5 * G * t * t
    np.testing.assert_allclose(paths["drake"], paths["mujoco"], atol=1e-6)
    p = paths["drake"]
    assert np.abs(p[:, :3] - exact).max() <= 9.81 * DT * t[-1, 0] / 2 + 1e-6
    np.testing.assert_allclose(p[:, 3:], v0 + G * t, atol=1e-9)


@pytest.mark.parametrize("model", ["point", "hydroelastic"])
def test_fast_ball_is_stopped_by_the_palm(model):
    """A 9 m/s ball thrown at the palm's face: a contact event on the palm (a point contact's or
    a hydroelastic patch's row), the ball turned back (its speed along the face normal reversed
    or stopped), never through the palm."""
    plant = make(**CATCHING)
    spec = plant.spec()
    T = spec.model.fk(np.asarray(START))
    n = T[:3, 2]
    face = T[:3, 3] + n * spec.hand.table.palm_thickness
    r0 = face + n * 0.1
    plant = make(
        object_position=r0.tolist(), object_velocity=(-9.0 * n).tolist(),
        dk_contact_model=model, **CATCHING,
    )  # fmt: skip
    contact = None
    for _ in range(60):
        plant.apply(ArmCommand(hold_torque(plant, START)))
        plant.step()
        for e in plant.pop_events():
            if e.kind == "contact" and contact is None:
                contact = e.data
    pos, _, v, _ = plant.object_state()
    assert contact is not None and "palm" in contact["parts"]
    assert contact["normal_speed"] > 5.0  # the normal points from the palm towards the ball
    assert float(v @ n) >= -0.5  # stopped or bounced back
    assert float((pos - face) @ n) > 0.0  # the ball's centre never passed the face


# ---------------------------------------------------------------- the grasping rig
def grasp_rig(**kw) -> DrakeGraspPlant:
    base = dict(
        arm="wam7",
        hand="grasp4",
        object="box",
        object_size=[0.05, 0.10, 0.05],
        object_mass=0.1,
        object_position=[0.75, 0.0, 0.55],
        initial_q=Q0,
        head_position=[0.0, 0.15, 0.70],
        human_speed=0.0,
        human_roll_rate=0.0,
        velocity_limits=[3.0] * 7,
    )  # fmt: skip  (tests/grasp_rig.py's rig)
    base.update(kw)
    return DrakeGraspPlant(GraspParams(**base), dt=DT, rng=np.random.default_rng(0))


def still(plant, steps: int = 300):
    cmd = ServoCommand(arm=[0.0] * 7, hand=[0.0] * 14, head=[0.0, 0.0])
    for _ in range(steps):
        plant.apply(cmd)
        plant.step()


def test_grasping_rig_held_still_stays_still():
    """The servos commanded to zero speed from their preloaded integrals: the arm stays within
    1e-3 rad of its initial posture over 0.3 s and ends at rest."""
    plant = grasp_rig()
    q0 = plant.arm_state()[0]
    still(plant)
    q, qd = plant.arm_state()
    assert np.abs(q - q0).max() < 1e-3
    assert np.abs(qd).max() < 1e-3


def test_wrist_reads_the_hanging_hand_as_pybullet_does():
    """The hand hanging still: the wrist reads its weight m g along gravity (palm frame) and
    r x m g about the joint (r: the whole hand's centre of mass), PyBullet's 7.0632 N and
    0.2478 N m (tests/plants/mujoco_arm/test_wrist_mujoco.py)."""
    plant = grasp_rig()
    still(plant)
    w = np.array(plant._wrench)
    _, orn, _, _ = plant.effector_state()
    x, y, z, s = orn
    R = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * s), 2 * (x * z + y * s)],
            [2 * (x * y + z * s), 1 - 2 * (x * x + z * z), 2 * (y * z - x * s)],
            [2 * (x * z - y * s), 2 * (y * z + x * s), 1 - 2 * (x * x + y * y)],
        ]
    )
    m = hand_mass(GRASP4)
    np.testing.assert_allclose(R @ w[:3], m * G, atol=1e-3)
    com = hand_body(GRASP4, plant.hand_state()[0]).com
    np.testing.assert_allclose(R @ w[3:], np.cross(R @ com, m * G), atol=1e-3)
    assert w[0] == pytest.approx(7.0632, abs=2e-3) and w[4] == pytest.approx(0.2478, abs=2e-3)


STEP = 0.05  # rad/s, as the PyBullet and MuJoCo tests: no joint reaches its torque limit
BANDWIDTH = 500.0  # rad/s: scenarios/grasp_hexahedron.yaml's arm_servo_bandwidth


def step_response(j: int, steps: int = 100) -> np.ndarray:
    plant = make(
        arm="wam7", hand="grasp4", object="none", initial_q=Q0,
        torque_limit_set="public_urdf", velocity_limits=[3.0] * 7,
    )  # fmt: skip
    p, ctx, v = plant.mbp, plant.ctx, list(plant.world.arm_v)

    def mass() -> np.ndarray:
        return p.CalcMassMatrix(ctx)[np.ix_(v, v)]

    servos = VelocityServos(plant.torque_limits, BANDWIDTH, DT)
    servos.preload((-p.CalcGravityGeneralizedForces(ctx)[v]).tolist(), mass())

    def run(cmd) -> None:
        servos.set_command(cmd)
        plant.apply(ArmCommand(torque=servos.torques(plant.arm_state()[1].tolist(), mass())))
        plant.step()

    for _ in range(50):
        run([0.0] * 7)
    w0 = plant.arm_state()[1]
    cmd = [0.0] * 7
    cmd[j] = STEP
    out = []
    for _ in range(steps):
        run(cmd)
        assert not any(servos.saturated_l)
        out.append(plant.arm_state()[1] - w0)
    return np.array(out)


@pytest.mark.parametrize("joint", range(7))
def test_each_arm_joint_has_the_stated_bandwidth_in_drake(joint):
    w = step_response(joint)
    got = rise_bandwidth(w[:, joint], STEP, DT)
    print(f"J{joint + 1}: {got:.0f} rad/s (stated {BANDWIDTH:.0f})")
    assert got == pytest.approx(BANDWIDTH, rel=0.2)
    assert w[-10:, joint] == pytest.approx(STEP, rel=0.02)
    assert np.abs(np.delete(w, joint, axis=1)).max() < 0.1 * STEP


# ---------------------------------------------------------------- the scenarios
@pytest.mark.parametrize(
    "name", ["catch_optimised", "catch_initial", "grasp_hexahedron", "grasp_sphere"]
)
def test_drake_scenario_differs_only_in_the_plant(name):
    """The resolved scenario of NAME_drake is NAME's with the Drake plant type and Drake's own
    settings added: every other field (plant params included) equal."""
    from replay.scenario import load_scenario
    from replay.scenario.loader import to_plain

    a = to_plain(load_scenario(ROOT / "scenarios" / f"{name}.yaml"))
    b = to_plain(load_scenario(ROOT / "scenarios" / f"{name}_drake.yaml"))
    assert b["plant"]["type"] == a["plant"]["type"].replace("bullet_", "drake_")
    pa, pb = a["plant"]["params"], b["plant"]["params"]
    assert {k: pb[k] for k in pa} == pa
    assert set(pb) - set(pa) == DK_FIELDS
    for key in set(a) - {"name", "description", "plant", "source"}:
        assert a[key] == b[key], key
    raw = yaml.safe_load((ROOT / "scenarios" / f"{name}_drake.yaml").read_text())
    assert raw.get("controller", {}).get("type") is None  # the method is inherited


def test_deterministic():
    """Two Drake plants from the same params step to bit-identical states."""

    def run():
        plant = make(object_position=[1.0, 0.0, 0.6], object_velocity=[-4.0, 0.0, 0.0], **CATCHING)
        for _ in range(200):
            plant.apply(ArmCommand(hold_torque(plant, START)))
            plant.step()
        return [a.tolist() for a in plant.object_state()] + [plant.arm_state()[0].tolist()]

    assert run() == run()


def bounce(speed: float, **kw) -> float:
    """The ball's speed back off the held arm's palm over its speed in (no gravity on it)."""
    probe = make(**CATCHING)
    spec = probe.spec()
    T = spec.model.fk(np.asarray(START))
    n = T[:3, 2]
    r0 = T[:3, 3] + n * (spec.hand.table.palm_thickness + 0.0175 + 0.01)
    plant = make(
        object_position=r0.tolist(), object_velocity=(-speed * n).tolist(),
        object_gravity=False, **CATCHING, **kw,
    )  # fmt: skip
    for _ in range(60):
        plant.apply(ArmCommand(hold_torque(plant, START)))
        plant.step()
    return float(plant.object_state()[2] @ n) / speed


def test_bounce_off_the_palm_is_the_documented_one():
    """plants/drake_arm/params.py's dk_dissipation: 0.08 of the speed back at 1.3 m/s, 0.02 at
    6 m/s (Hunt-Crossley's bounce falls with the speed), 0.22 at both without dissipation."""
    assert bounce(1.3) == pytest.approx(0.08, abs=0.01)
    assert bounce(6.0) == pytest.approx(0.02, abs=0.01)
    assert bounce(1.3, dk_dissipation=0.0) == pytest.approx(0.22, abs=0.02)
    assert bounce(6.0, dk_dissipation=0.0) == pytest.approx(0.22, abs=0.02)
