"""What the arm-engine tests share: a test-side hold torque, and the seeded perturbed throws of
tests/analysis/test_catch_robustness.py run through a scenario (conftest puts tests/ on the
path)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def hold_torque(plant, q_ref, omega=30.0):
    """A test-side joint PD + gravity compensation from the nominal model (not the plant's);
    gains from M's diagonal, so that each joint is a ~critically damped omega rad/s loop."""
    q, qd = plant.arm_state()
    model = plant.spec().model
    m = np.diag(model.mass_matrix(q))
    return model.gravity_torque(q) + m * omega**2 * (np.asarray(q_ref) - q) - 2.0 * m * omega * qd


def _robustness_module():
    spec = importlib.util.spec_from_file_location(
        "catch_robustness", ROOT / "tests" / "analysis" / "test_catch_robustness.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


robust = _robustness_module()  # its throw generator, seed and N_THROWS


def run_throws(name: str, throws: list, out: Path, sets: dict | None = None) -> list[tuple]:
    """(outcome, log path) of scenario ``name`` on each throw, ``sets`` (a plant.params field
    path -> YAML) applied on top of the throw's."""
    from replay.runner import Runner
    from replay.scenario import load_scenario

    fmt = lambda v: "[" + ", ".join(f"{x:.6f}" for x in v) + "]"  # noqa: E731
    res = []
    for i, th in enumerate(throws):
        args = [
            f"plant.params.object_position={fmt(th['position'])}",
            f"plant.params.object_velocity={fmt(th['velocity'])}",
            "timing.duration=0.45",
            "stop.after=0.0",
        ] + [f"plant.params.{k}={v}" for k, v in (sets or {}).items()]
        r = Runner(load_scenario(ROOT / "scenarios" / f"{name}.yaml", args)).run(out / f"{i}.mcap")
        assert "warning" not in r.events, "stale alpha file"
        res.append((r.outcome, r.path))
    return res
