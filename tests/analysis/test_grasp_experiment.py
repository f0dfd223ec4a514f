"""The grasping experiment end to end (Namiki, Nakabo, Ishii & Ishikawa 1999): the hexahedron and
the sphere are grasped with their own preshape while the human keeps moving them, every loop
ticks each 1 ms with its sensor-to-actuator latency under 1.5 ms, a missed grasp says why, and
a seeded randomised run over other human paths and speeds reports the grasp rate."""

from __future__ import annotations

import numpy as np
import pytest

from replay.log import LogReader
from replay.runner import Runner
from replay.scenario import load_scenario


def run(tmp_path, name, sets=(), seed=None):
    sc = load_scenario(f"scenarios/{name}.yaml", sets=list(sets), seed=seed)
    out = tmp_path / f"{name}_{seed}_{abs(hash(tuple(sets))) % 10**6}.mcap"
    result = Runner(sc).run(out)
    return result, LogReader(out)


@pytest.fixture(scope="module")
def hexahedron(tmp_path_factory, project_root_module):
    """The scenario as it is (2 s: tracking, reach, then the hold). The grasp's moment moves
    with the low bits of the machine's BLAS kernels (the contacts are chaotic); since issue #20
    the object is at rest in the hand from ~0.82 s (the grasp event 50 ms later) and held ~1.1 s
    to the end (test_the_box_is_grasped_with_another_machines_blas_kernels runs others)."""
    return run(tmp_path_factory.mktemp("grasp"), "grasp_hexahedron")


@pytest.fixture(scope="module")
def project_root_module():
    import os
    from pathlib import Path

    old = os.getcwd()
    os.chdir(Path(__file__).resolve().parents[2])
    yield
    os.chdir(old)


def events(log, kind):
    return [e for e in log.events() if e["kind"] == kind]


def test_the_box_is_grasped_with_the_rectangle_preshape_and_held_while_it_moves(hexahedron):
    result, log = hexahedron
    o = result.outcome
    assert o["success"], o["reason"]
    assert o["shape"] == "rectangle" and o["preshape_at_grasp"] == ["rectangle"]
    # reaching 0.5-0.8 s (Fig. 7); the fingers close and settle after it (1.0-1.13 s measured)
    assert 0.8 < o["first_grasp_t"] < 1.3
    assert o["held_path"] > 0.01  # the human kept moving it, m
    grasp = events(log, "grasp")
    assert len(grasp) == 1 and len(grasp[0]["data"]["parts"]) >= 3
    assert not events(log, "release") and not events(log, "drop")


def test_every_loop_ticks_each_ms_with_latency_under_1_5_ms(hexahedron):
    _, log = hexahedron
    loops = log.series("/tasks/loops")
    assert len(loops) == 2000
    assert all(all(m["ticked"]) for m in loops)
    names = loops[0]["names"]
    assert all(x is None for m in loops for x, n in zip(m["latency"], names) if n == "schedule")
    worst = {
        n: max(m["latency"][i] for m in loops[10:]) for i, n in enumerate(names) if n != "schedule"
    }  # the schedule reads no sensor
    print("worst sensor-to-actuator latency per loop (s):", worst)
    for name in ("vision", "head", "arm", "hand"):
        assert worst[name] <= 0.0015 + 1e-12
    assert worst["vision"] == pytest.approx(0.001)  # the chip's one frame
    assert worst["hand"] == pytest.approx(0.001)  # via the recognised shape


def test_tracking_follows_the_object_before_the_reach(hexahedron):
    """Tracking without prediction: while only tracking (0.1-0.5 s) the hand's grasp point
    stays within 2 cm of the moving object in the plane (truth, not the method's estimate)."""
    _, log = hexahedron
    arm = [m for m in log.series("/grasping/arm") if 0.1 <= m["t"] < 0.5]
    obj = {round(m["t"], 6): m["position"] for m in log.series("/object/state")}
    err = [
        np.hypot(a["x_a"][1] - obj[round(a["t"], 6)][1], a["x_a"][2] - obj[round(a["t"], 6)][2])
        for a in arm
    ]
    moved = np.ptp([obj[round(a["t"], 6)][1:] for a in arm], axis=0).max()
    assert moved > 0.01
    assert max(err) < 0.02


def test_the_ball_gets_the_circle_preshape_and_is_grasped(tmp_path, project_root):
    result, log = run(tmp_path, "grasp_sphere", ["timing.duration=1.8"])
    o = result.outcome
    assert o["success"], o["reason"]
    assert o["shape"] == "circle" and o["preshape_at_grasp"] == ["circle"]
    pre = events(log, "preshape")
    assert [e["data"]["shape"] for e in pre] == ["circle"]


def test_a_grasp_that_stops_short_says_why(tmp_path, project_root):
    """The reach ends 12 cm before the object (x_grasp = 0.12 m): the fingers close on nothing
    (at touch_speed, ~0.25 s from the touch posture to the grip); the run fails and says so."""
    result, _ = run(
        tmp_path, "grasp_hexahedron", ["timing.duration=1.3", "tasks.schedule.params.x_grasp=0.12"]
    )
    o = result.outcome
    assert o["success"] is False
    assert o["reason"].startswith("no grasp")
    assert o["missed"] and "closed on nothing" in o["missed"][0]["why"]


def test_grasp_rate_over_other_human_paths_and_speeds(tmp_path, project_root):
    """Seeded randomised: other seeds (other band-limited paths) and human speeds around the
    scenario's 0.10 m/s RMS. Reports the grasp rate; the method must grasp most of them."""
    cases = [(11, 0.05), (12, 0.10), (13, 0.15), (14, 0.10)]
    ok = []
    for seed, speed in cases:
        result, _ = run(
            tmp_path,
            "grasp_hexahedron",
            ["timing.duration=1.8", f"plant.params.human_speed={speed}"],
            seed=seed,
        )
        ok.append(result.outcome["success"])
        print(f"seed {seed}, human {speed} m/s: {result.outcome['reason']}")
    rate = sum(ok) / len(ok)
    print(f"grasp rate {sum(ok)}/{len(ok)} = {rate:.0%}")
    assert rate >= 0.75


def test_same_seed_same_log(tmp_path, project_root):
    logs = []
    for sub in ("a", "b"):
        (tmp_path / sub).mkdir()
        logs.append(run(tmp_path / sub, "grasp_hexahedron", ["timing.duration=0.15"])[1])
    for topic in (
        "/vision/chip",
        "/grasping/object",
        "/grasping/arm",
        "/object/state",
        "/human/state",
        "/wrist/wrench",
    ):
        assert logs[0].series(topic) == logs[1].series(topic), topic


@pytest.mark.parametrize("kernels", ["Haswell", "Prescott"])
def test_the_box_is_grasped_with_another_machines_blas_kernels(kernels, tmp_path, project_root):
    """Another CPU's BLAS (OpenBLAS's kernels for it, chosen by OPENBLAS_CORETYPE at start-up)
    changes the low bits of the arm's damped pseudo-inverse and from there the contacts: the
    grasp must not depend on them."""
    import os
    import subprocess
    import sys

    out = tmp_path / "grasp.mcap"
    env = {**os.environ, "OPENBLAS_CORETYPE": kernels}
    subprocess.run(
        [
            sys.executable,
            "-m",
            "replay.cli",
            "run",
            "scenarios/grasp_hexahedron.yaml",
            "-o",
            str(out),
        ],
        check=True,
        env=env,
        capture_output=True,
    )
    o = [e for e in LogReader(out).events() if e["kind"] == "outcome"][-1]["data"]
    print(f"{kernels}: {o['reason']}, first grasp {o['first_grasp_t']:.3f} s")
    assert o["success"], o["reason"]
    assert 0.8 < o["first_grasp_t"] < 1.3
