"""The package as a user installs it: a non-editable wheel in a fresh venv, used from an empty
directory (no checkout on the path), finds its scenarios, robot tables, claims and inputs."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _sh(args, cwd, timeout=900, env=None):
    r = subprocess.run(
        [str(a) for a in args], cwd=cwd, capture_output=True, text=True, timeout=timeout, env=env
    )
    assert r.returncode == 0, f"{args}: rc {r.returncode}\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    return r.stdout + r.stderr


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    base = tmp_path_factory.mktemp("wheel")
    dist, venv, work = base / "dist", base / "venv", base / "empty"
    work.mkdir()
    _sh(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "-q",
            "--no-deps",
            "--no-build-isolation",
            "-w",
            dist,
            ROOT,
        ],
        cwd=base,
    )
    wheel = next(dist.glob("paper_replay-*.whl"))
    _sh([sys.executable, "-m", "venv", venv], cwd=base)
    _sh([venv / "bin" / "python", "-m", "pip", "install", "-q", wheel], cwd=base)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    return venv / "bin" / "replay", work, env


def test_the_wheel_ships_its_data(installed):
    replay, work, env = installed
    out = _sh([replay, "list"], cwd=work, env=env)
    for name in ("stick_3step", "catch_optimised"):
        assert name in out
    assert "invalid" not in out


def test_one_run_of_each_paper_from_an_empty_directory(installed):
    replay, work, env = installed
    for name in ("stick_3step", "catch_optimised", "grasp_hexahedron"):
        out = _sh(
            [
                replay,
                "run",
                name,
                "--quiet",
                "--set",
                "timing.duration=0.3",
                "-o",
                work / f"{name}.mcap",
            ],
            cwd=work,
            env=env,
        )
        assert (work / f"{name}.mcap").is_file(), out
        assert "Traceback" not in out and "pybullet build time" not in out, out
        info = _sh([replay, "info", work / f"{name}.mcap"], cwd=work, env=env)
        assert "outcome" in info
    out = _sh([replay, "claims", *sorted(work.glob("*.mcap"))], cwd=work, env=env)
    assert "Traceback" not in out
    for title in ("Stick-shaped", "Direct Mapping", "High Speed Grasping"):  # all three tables
        assert title in out, out[-2000:]
    report = work / "report"
    out = _sh([replay, "report", "-o", report, "--logs", work], cwd=work, env=env)
    html = (report / "index.html").read_text(encoding="utf-8")
    images = re.findall(r"<img src='([^']+)'", html)
    assert images, "the report shows no figure"
    missing = [src for src in images if not (report / src).is_file()]
    assert not missing, missing
    _sh([replay, "figures", *sorted(work.glob("*.mcap")), "-o", work / "figs"], cwd=work, env=env)
    assert any((work / "figs").glob("*.png"))
    out = _sh([replay, "golden", "check", "stick_3step"], cwd=work, env=env)
    assert "ok" in out


def test_a_user_scenario_builds_on_a_shipped_one(installed):
    """``replay show`` copies one out; ``extends: NAME`` resolves a shipped scenario by name."""
    replay, work, env = installed
    _sh([replay, "show", "stick_3step", "-o", work / "copy.yaml"], cwd=work, env=env)
    (work / "mine.yaml").write_text("extends: stick_3step\nseed: 5\ntiming:\n  duration: 0.2\n")
    for f in ("copy.yaml", "mine.yaml"):
        out = _sh([replay, "run", f, "--quiet", "-o", work / f"{f}.mcap"], cwd=work, env=env)
        assert (work / f"{f}.mcap").is_file(), out
    assert "seed 5" in _sh([replay, "info", work / "mine.yaml.mcap"], cwd=work, env=env)
