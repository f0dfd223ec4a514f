"""The package as a user installs it: a non-editable wheel in a fresh venv, used from an empty
directory (no checkout on the path), finds its scenarios, robot tables, claims and inputs."""

import os
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
    for name in ("stick_3step", "catch_optimised"):
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
        info = _sh([replay, "info", work / f"{name}.mcap"], cwd=work, env=env)
        assert "outcome" in info
    _sh([replay, "claims", *sorted(work.glob("*.mcap"))], cwd=work, env=env)
    _sh([replay, "figures", *sorted(work.glob("*.mcap")), "-o", work / "figs"], cwd=work, env=env)
    assert any((work / "figs").glob("*.png"))
    out = _sh([replay, "golden", "check", "stick_3step"], cwd=work, env=env)
    assert "ok" in out
