"""Packaging guarantees: the installed top-level packages are not shadowed by a user's folder of
the same name, and the code's commit is known from a checkout and from a build (issue #37)."""

from __future__ import annotations

import subprocess
import sys
import types
from pathlib import Path

import pytest

from replay import version

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def decoys(tmp_path_factory):
    """A folder holding ``analysis/`` and ``plants/`` packages of a user's own, and a short
    stick run's log."""
    folder = tmp_path_factory.mktemp("decoys")
    for name in ("analysis", "plants"):
        (folder / name).mkdir()
        (folder / name / "__init__.py").write_text(f"MINE = {name!r}\n")
    r = subprocess.run(
        [sys.executable, "-m", "replay.cli", "run", "stick_3step", "--quiet"]
        + ["--set", "timing.duration=0.3", "-o", "s.mcap"],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert r.returncode == 0, r.stderr
    return folder


def test_python_m_from_a_folder_with_decoys_uses_the_installed_packages(decoys):
    """``python -m`` puts the current directory first on sys.path: without the guard, the run
    failed on ``plants.airtable`` and figures on ``analysis.stick.figures``."""
    for command in (["figures", "s.mcap", "-o", "figs"], ["claims", "s.mcap"]):
        r = subprocess.run(
            [sys.executable, "-m", "replay.cli", *command],
            cwd=decoys,
            capture_output=True,
            text=True,
            timeout=180,
        )
        assert r.returncode == 0, r.stderr
        assert "ModuleNotFoundError" not in r.stderr and "Traceback" not in r.stderr
    assert (decoys / "figs" / "stick_3step_fig7.png").is_file()


def test_a_notebook_importing_replay_first_gets_the_installed_packages(decoys):
    code = (
        "import sys; sys.path.insert(0, '')\n"  # (a notebook's cwd first, as Jupyter puts it)
        "import replay.registry, analysis.stick.figures, plants.airtable, analysis, plants\n"
        "print(analysis.__file__); print(plants.__file__)\n"
    )
    r = subprocess.run(
        [sys.executable, "-c", code], cwd=decoys, capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 0, r.stderr
    assert str(decoys) not in r.stdout
    for line, name in zip(r.stdout.split(), ("analysis", "plants")):
        assert Path(line).parent.name == name and Path(line).parent.parent == ROOT


def test_a_plugin_folder_goes_last_on_the_path(tmp_path, monkeypatch):
    """A scenario's folder holding ``analysis/`` does not shadow the installed one either."""
    from replay import registry

    (tmp_path / "analysis").mkdir()
    (tmp_path / "analysis" / "__init__.py").write_text("")
    monkeypatch.setattr(sys, "path", list(sys.path))
    with pytest.raises(registry.UnknownPlugin, match="has no 'Nothing'"):
        registry.import_plugin("controller", "analysis:Nothing", tmp_path)
    assert sys.path[-1] == str(tmp_path.resolve())
    import analysis

    assert Path(analysis.__file__).parent.parent == ROOT


# -- the code's commit ----------------------------------------------------------------------------


def _git(*args, cwd):
    subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True, timeout=30)


def test_the_checkout_reads_its_commit_live_and_a_build_its_recorded_one(monkeypatch):
    head = subprocess.run(
        ["git", "rev-parse", "--short=12", "HEAD"], cwd=ROOT, capture_output=True, text=True
    ).stdout.strip()
    assert version.commit.__wrapped__() == head
    assert version.code_version().startswith(f"0.1.0+{head}")
    assert not (ROOT / "replay" / "_build_info.py").exists()  # (a build writes it in build/)
    built = types.SimpleNamespace(COMMIT="0123456789ab", DIFF="")
    monkeypatch.setitem(sys.modules, "replay._build_info", built)
    assert version.commit.__wrapped__() == "0123456789ab"
    assert version.code_version().endswith("+0123456789ab")


def test_a_folder_inside_another_repository_has_no_commit(tmp_path):
    """A venv inside a user's own git project: that project's commit is not this code's."""
    _git("init", "-q", cwd=tmp_path)
    _git(
        "-c",
        "user.name=t",
        "-c",
        "user.email=t@t",
        "commit",
        "-q",
        "--allow-empty",
        "-m",
        "x",
        cwd=tmp_path,
    )
    inner = tmp_path / "venv" / "site-packages"
    inner.mkdir(parents=True)
    assert version.git_state(inner) == ("", "")
    sha, digest = version.git_state(tmp_path)
    assert len(sha) == 12 and digest == ""
    (tmp_path / "f.txt").write_text("a")
    _git("add", "f.txt", cwd=tmp_path)
    assert len(version.git_state(tmp_path)[1]) == 8  # uncommitted changes: a digest
