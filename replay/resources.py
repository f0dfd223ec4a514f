"""Where the shipped files are: scenarios, robot tables, the papers' stated numbers, precomputed
inputs and golden logs.

In a source checkout they are the top-level ``scenarios/`` and ``data/`` folders; in an installed
wheel the same folders are package data under ``replay._shipped`` (pyproject.toml maps them), found
with :mod:`importlib.resources`. Nothing here depends on the working directory.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

_CHECKOUT = Path(__file__).resolve().parents[1]

# where `replay run` writes a log by default, and where the analysis commands look for logs
DEFAULT_LOG_DIR = Path("out/logs")


def _root(kind: str) -> Path:
    local = _CHECKOUT / kind
    if (_CHECKOUT / "pyproject.toml").is_file() and local.is_dir():
        return local  # a source checkout (editable install)
    return Path(str(resources.files("replay._shipped") / kind))  # an installed wheel


def shipped_root() -> Path:
    """The folder holding ``data/`` and ``scenarios/`` (paths in data/golden/manifest.yaml are
    relative to it)."""
    return _root("data").parent


def data_path(*parts: str) -> Path:
    """A file or folder under the shipped ``data/`` (e.g. ``data_path("robots", "wam.yaml")``)."""
    return _root("data").joinpath(*parts)


def scenario_dir() -> Path:
    """The shipped scenarios folder."""
    return _root("scenarios")


def sweep_dir() -> Path:
    """The shipped sweep files (the ablations, ``replay ablate``)."""
    return _root("sweeps")


def find_scenario(arg: str) -> str:
    """A scenario argument as a path: an existing file wins; else a bare name (``stick_3step``
    or ``stick_3step.yaml``, as ``extends:`` takes it) is a shipped scenario; else the argument
    as given (the loader says it does not exist)."""
    if Path(arg).exists() or "/" in arg or "\\" in arg or not arg:
        return arg
    name = arg if arg.endswith((".yaml", ".yml")) else f"{arg}.yaml"
    shipped = scenario_dir() / name
    return str(shipped) if shipped.is_file() else arg
