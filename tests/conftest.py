import signal
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))


# The files that take longest, longest first (their time in `make test` on 2 quiet workers,
# 2026-12-05, `--durations=0` summed per file): they run before every other file, so that with
# `make test`'s --dist loadfile --no-loadscope-reorder the two workers start on the longest and
# the short files fill the end, instead of a long one starting last (xdist's own order is by
# test count). The browser pages and the wheel's `replay` subprocesses are mostly waiting.
LONGEST_FIRST = (
    "tests/replay/test_wheel_install.py",  # ~89 s: two wheels built, runs and analysis from each
    "tests/replay/viewer/test_viewer_browser.py",  # ~56 s: 8 pages in Chromium's software WebGL
    "tests/analysis/test_falsify.py",  # ~48 s: `replay falsify` of the three papers
    "tests/replay/control/predictive/test_predictive.py",  # ~31 s
    "tests/analysis/test_any_runs.py",  # ~27 s
    "tests/plants/drake_arm/test_grasp_drake.py",  # ~23 s
    "tests/replay/viewer/test_viewer_browser_framing.py",  # ~21 s
    "tests/replay/test_hostile_outputs.py",  # ~21 s
    "tests/plants/mujoco_arm/test_grasp_mujoco.py",  # ~20 s
    "tests/replay/sweep/test_ray_cluster.py",  # ~15 s
)


def pytest_collection_modifyitems(items):
    rank = {path: k for k, path in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(rank)))  # (stable)


@pytest.fixture(autouse=True, scope="session")
def _toy_plugins():
    import toy_plugins

    toy_plugins.install()


@pytest.fixture(autouse=True)
def _sigint_left_as_found():
    """Each test leaves Python's SIGINT handler as it found it. A test that leaves another one
    (SIG_IGN, a log writer's held-SIGINT handler) fails here, by name, instead of the Ctrl-C tests
    that follow it: a child inherits an ignored SIGINT, and a writer installs its handler only
    over the default one. The handler is put back either way."""
    before = signal.getsignal(signal.SIGINT)
    yield
    after = signal.getsignal(signal.SIGINT)
    if after is not before:
        signal.signal(signal.SIGINT, before)
        pytest.fail(f"the test left SIGINT's handler {after!r} (it found {before!r})")


@pytest.fixture
def project_root(monkeypatch):
    """Run from the project root, where scenarios/ and data/ are."""
    monkeypatch.chdir(ROOT)
    return ROOT


TOY = """\
name: toy
paper: none
description: a point mass pushed to a target
seed: 3
timing: {physics_rate: 1000, duration: 1.0}
plant:
  type: toy
  params: {mass: 2.0}
sensors:
  cam: {type: toy_sensor, rate: 100, latency: 0.02}
controller: {type: toy_pd, rate: 500, params: {target: 1.0}}
"""


@pytest.fixture
def toy_yaml(tmp_path):
    p = tmp_path / "toy.yaml"
    p.write_text(TOY)
    return p


def fail_writes_after(monkeypatch, n: int) -> list[int]:
    """Make the log file's writes fail as a full disk (ENOSPC) after the first ``n``: the
    sizes of the writes tried, in order, are appended to the returned list."""
    import errno
    import os

    from replay.log.writer import _FlushedFile

    write, calls = _FlushedFile.write, []

    def full(self, data):
        calls.append(len(data))
        if len(calls) > n:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return write(self, data)

    monkeypatch.setattr(_FlushedFile, "write", full)
    return calls


@pytest.fixture(scope="session")
def stick_3step_log(tmp_path_factory):
    """A finished stick_3step run's log, made once for the session (do not change it: copy it)."""
    from cli_checks import invoke

    path = tmp_path_factory.mktemp("base") / "stick_3step.mcap"
    r = invoke("run", "stick_3step", "-q", "-o", path)
    assert r.exit_code == 0, r.output
    return path
