"""docs/DESIGN.md's "Adding a fourth paper" is true (issue #40): followed in a copy of the
checkout, its files and its one registration make a paper that runs, draws its figure and judges
its claim, and it names at most one folder per top-level directory."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
REPLAY = [sys.executable, "-m", "replay.cli"]


def _section() -> str:
    text = (ROOT / "docs" / "DESIGN.md").read_text(encoding="utf-8")
    start = text.index("## Adding a fourth paper")
    return text[start : text.index("\n## ", start + 1)]


def _files(section: str) -> dict[str, str]:
    """Path -> text of every code block: a block's path is the last `path` named before it in
    the text, or its own first line's ``# path`` comment."""
    files: dict[str, str] = {}
    pos = 0
    for block in re.finditer(r"```(\w+)\n(.*?)```", section, re.S):
        body = block.group(2)
        own = re.match(r"# ([\w/.]+\.\w+)\n", body)
        if own:
            files[own.group(1)] = body[own.end() :]
        else:
            named = re.findall(r"`([\w/.]+\.(?:py|yaml|toml))`", section[pos : block.start()])
            files[named[-1]] = body
        pos = block.end()
    return files


def _register(copy: Path, site: Path) -> None:
    """What ``make install`` does for entry points: the copy's pyproject.toml's groups as an
    installed distribution's entry_points.txt."""
    groups = tomllib.loads((copy / "pyproject.toml").read_text())["project"]["entry-points"]
    info = site / "paper_replay_copy-0.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: paper-replay-copy\nVersion: 0\n")
    lines = [
        f"[{g}]\n" + "".join(f"{k} = {v}\n" for k, v in eps.items()) for g, eps in groups.items()
    ]
    (info / "entry_points.txt").write_text("\n".join(lines))


def _add(copy: Path, path: str, text: str) -> None:
    target = copy / path
    if path == "pyproject.toml":  # lines added under the table the block names
        header, *entries = text.strip().splitlines()
        old = target.read_text()
        assert header in old, header
        target.write_text(old.replace(header, "\n".join([header, *entries]), 1))
        return
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(text)


def test_the_walkthrough_names_one_folder_per_top_level_directory():
    files = [p for p in _files(_section()) if "/" in p]
    folders: dict[str, set[str]] = {}
    for p in files:
        top, rest = p.split("/", 1)
        folders.setdefault(top, set()).add(rest.rsplit("/", 1)[0] if "/" in rest else ".")
    assert set(folders) >= {"replay", "plants", "analysis", "scenarios"}
    assert all(len(v) == 1 for v in folders.values()), folders
    assert "pyproject.toml" in _files(_section())  # the one registration


@pytest.fixture(scope="module")
def toy_paper(tmp_path_factory) -> tuple[Path, dict[str, str]]:
    """A copy of the checkout with the walk-through's files and registration, and the
    environment that runs ``replay`` from it."""
    base = tmp_path_factory.mktemp("fourth_paper")
    copy = base / "checkout"
    skip = shutil.ignore_patterns("__pycache__", "*.pyc")
    for top in ("replay", "plants", "analysis"):
        shutil.copytree(ROOT / top, copy / top, ignore=skip)
    shutil.copy(ROOT / "pyproject.toml", copy / "pyproject.toml")
    (copy / "scenarios").mkdir()
    (copy / "analysis" / "toy2026").mkdir()
    (copy / "analysis" / "toy2026" / "__init__.py").write_text("")  # ("is empty")
    for path, text in _files(_section()).items():
        _add(copy, path, text)
    _register(copy, base / "site")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(copy), str(base / "site")])}
    return copy, env


def _replay(toy_paper, *args: str) -> str:
    copy, env = toy_paper
    r = subprocess.run([*REPLAY, *args], cwd=copy, env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    return r.stdout


def test_the_fourth_paper_runs_and_is_drawn_and_judged(toy_paper):
    copy, _ = toy_paper
    listed = _replay(toy_paper, "list", "--plugins")
    assert "toy_reach" in listed and "toy_line" in listed and "toy2026" in listed
    assert "stick_3step" in listed and "namiki2003" in listed  # (the three papers still are)
    _replay(toy_paper, "run", "scenarios/toy2026_reach.yaml", "-o", "toy.mcap")
    assert (copy / "toy.mcap").is_file()
    _replay(toy_paper, "figures", "toy.mcap", "-o", "figs")
    assert (copy / "figs" / "toy2026_reach_fig1.png").stat().st_size > 1000
    claims = _replay(toy_paper, "claims", "toy.mcap")
    row = next(line for line in claims.splitlines() if "stops within 1 cm" in line)
    assert "reproduced" in row, claims
    assert "Reaching a Target on a Line" in claims  # (the registration's title)


def test_the_copy_runs_its_own_code(toy_paper):
    """(The test would prove nothing if the installed checkout answered instead of the copy.)"""
    copy, env = toy_paper
    code = "import replay, analysis.toy2026.paper as p; print(replay.__file__, p.__file__)"
    out = subprocess.run([sys.executable, "-c", code], cwd=copy, env=env, capture_output=True)
    assert out.returncode == 0, out.stderr
    assert all(Path(f).is_relative_to(copy) for f in out.stdout.decode().split())
