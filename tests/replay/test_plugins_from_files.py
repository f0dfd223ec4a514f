"""Plug-ins named by import path (``type: module:Class``) without packaging, a ``--set`` that
changes a plug-in's type, and logs read where their plug-ins are not installed (issue #37)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import uuid
from pathlib import Path

import pytest

from replay import registry
from replay.runner import Runner
from replay.scenario import ScenarioError, load_scenario, resolved_yaml, scenario_from_text
from replay.scenario.schema import Scenario

ROOT = Path(__file__).resolve().parents[2]
REPLAY = [sys.executable, "-m", "replay.cli"]

CONTROLLER = """\
from dataclasses import dataclass
from replay.interfaces import Controller
from replay.params import param

@dataclass
class HoldParams:
    force: float = param(1.0, unit="N")

class Hold(Controller):
    Params = HoldParams
    def update(self, t, measurements):
        return self.params.force

class NoUpdate(Controller):
    Params = HoldParams

not_a_class = 3
"""

SCENARIO = """\
name: toy_from_file
paper: toy
timing: {{physics_rate: 100, duration: 0.05}}
plant: {{type: toy}}
sensors: {{pos: {{type: toy_sensor, rate: 100}}}}
controller:
  type: {type}
  rate: 100
  params: {params}
"""


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """A folder holding a controller module (a fresh name: modules are imported once a
    process), the module's name; sys.path and the imported plug-ins restored afterwards."""
    name = f"h8_ctrl_{uuid.uuid4().hex[:8]}"
    (tmp_path / f"{name}.py").write_text(CONTROLLER)
    monkeypatch.setattr(sys, "path", list(sys.path))
    monkeypatch.setattr(
        registry, "_imported", {kind: dict(v) for kind, v in registry._imported.items()}
    )
    run_dir = tmp_path / "elsewhere"
    run_dir.mkdir()
    monkeypatch.chdir(run_dir)
    yield tmp_path, name
    sys.modules.pop(name, None)


def _scenario(folder: Path, type_: str, params: str = "{force: 2.0}") -> Path:
    path = folder / "mine.yaml"
    path.write_text(SCENARIO.format(type=type_, params=params))
    return path


def test_a_controller_beside_the_scenario_file_runs(folder, tmp_path):
    where, name = folder
    sc = load_scenario(_scenario(where, f"{name}:Hold"))
    assert type(sc.controller.params).__name__ == "HoldParams"
    assert sc.controller.params.force == 2.0
    assert str(where.resolve()) == sys.path[-1]  # appended: installed packages still win
    result = Runner(sc).run(tmp_path / "run.mcap")
    assert result.stopped_by != "error", result.error
    assert f"type: {name}:Hold" in resolved_yaml(sc)


def test_set_names_a_module_in_the_current_directory(folder, monkeypatch):
    where, name = folder
    monkeypatch.chdir(where)
    base = _scenario(where / "elsewhere", "toy_pd", "{target: 2.0}")
    sc = load_scenario(base, sets=[f"controller.type={name}:Hold"])
    assert sc.controller.params.force == 1.0  # toy_pd's target dropped with its type


@pytest.mark.parametrize(
    "type_, expected",
    [
        ("h8_no_such_module_zz:Hold", "no module 'h8_no_such_module_zz'"),
        ("{name}:Missing", "has no 'Missing'"),
        ("{name}:not_a_class", "is not a class implementing replay.interfaces.Controller"),
        ("{name}:NoUpdate", "does not implement update"),
        ("{name}:Hold:x", "bad import path"),
    ],
)
def test_a_bad_import_path_is_one_line_at_the_type(folder, type_, expected):
    where, name = folder
    path = _scenario(where, type_.format(name=name))
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    text = str(err.value)
    assert expected in text and "controller.type" in text and "mine.yaml:7:9" in text
    assert "\n" not in text


def test_a_module_that_fails_to_import_is_one_line(folder):
    where, _ = folder
    (where / "h8_broken.py").write_text("def oops(:\n")
    (where / "h8_raises.py").write_text("raise RuntimeError('no GPU here\\nsecond line')\n")
    for mod, expected in (
        ("h8_broken", "SyntaxError"),
        ("h8_raises", "RuntimeError: no GPU here"),
    ):
        with pytest.raises(ScenarioError) as err:
            load_scenario(_scenario(where, f"{mod}:X"))
        assert expected in str(err.value) and "\n" not in str(err.value), err.value
        sys.modules.pop(mod, None)


def test_the_cli_runs_a_plugin_from_a_file_and_refuses_a_bad_one(tmp_path):
    """``replay run`` by path (the scenario's folder imported from, cwd elsewhere), and the
    one-line refusal with exit code 2."""
    shutil.copy(ROOT / "examples" / "my_controller.py", tmp_path)
    shutil.copy(ROOT / "examples" / "my_controller.yaml", tmp_path)
    bad = tmp_path / "bad.yaml"
    bad.write_text("extends: my_controller.yaml\ncontroller: {type: my_controller:Nope}\n")
    cwd = tmp_path / "cwd"
    cwd.mkdir()
    r = subprocess.run(
        [*REPLAY, "validate", tmp_path / "my_controller.yaml", bad],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 2, r.stderr
    assert "ok: " in r.stdout and "my_controller.yaml" in r.stdout
    lines = r.stderr.strip().splitlines()
    errors = [line for line in lines if line.startswith("error: ")]
    assert len(errors) == 1 and "has no 'Nope'" in errors[0] and "Traceback" not in r.stderr
    # the good one validates, with a warning: GoalKeeper publishes less than the paper's figures read
    warnings = [line for line in lines if line.startswith("warning: ")]
    assert len(warnings) == 1 and "/effector/state" in warnings[0], lines
    assert len(lines) == 2


def test_set_type_drops_the_old_params():
    """catch_optimised's controller params belong to the direct mapping: feedback refused them
    (``controller.params.mapping: unknown field``)."""
    sc = load_scenario(
        ROOT / "scenarios" / "catch_optimised.yaml", sets=["controller.type=feedback"]
    )
    assert type(sc.controller.params).__name__ == "FeedbackParams"
    assert sc.controller.rate == 1000  # only params go: rate is the runner's
    # the order of the --set does not matter: a type first, then the params given with it
    for sets in (
        ["controller.params.close_distance=0.2", "controller.type=feedback"],
        ["controller.type=feedback", "controller.params.close_distance=0.2"],
    ):
        sc = load_scenario(ROOT / "scenarios" / "catch_optimised.yaml", sets=sets)
        assert sc.controller.params.close_distance == 0.2
    same = load_scenario(
        ROOT / "scenarios" / "catch_feedback.yaml", sets=["controller.type=feedback"]
    )
    assert same.controller.params.close_distance == 0.15  # the same type keeps its params


def test_the_cli_runs_a_shipped_scenario_with_another_controller(tmp_path):
    r = subprocess.run(
        [*REPLAY, "run", "catch_optimised", "--set", "controller.type=feedback", "--quiet"]
        + ["--set", "timing.duration=0.05", "-o", tmp_path / "fb.mcap"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "fb.mcap").is_file()


# -- reading a log whose plug-ins are not here -------------------------------------------------


def _stored(controller_type: str) -> str:
    """A catch run's resolved scenario text with its controller swapped for one not here."""
    sc = load_scenario(ROOT / "scenarios" / "catch_optimised.yaml")
    text = resolved_yaml(sc)
    return text.replace("type: catching", f"type: {controller_type}", 1)


@pytest.mark.parametrize("ctrl", ["mine", "h8_colleague_mod:Theirs"])
def test_a_stored_scenario_is_read_without_its_plugins(ctrl, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    # a module of that name in the cwd: reading must never import it
    (tmp_path / "h8_colleague_mod.py").write_text("open('imported.marker', 'w').write('ran')\n")
    text = _stored(ctrl)
    with pytest.raises(ScenarioError, match="controller.type"):
        scenario_from_text(text)  # run-checked: the plug-in is not available
    sc = scenario_from_text(text, name="x.mcap:/scenario", plugins="known-only")
    assert isinstance(sc, Scenario)
    assert sc.plant.params.arm == "wam4"  # installed plug-ins: typed
    assert not isinstance(sc.sensors["stereo"].params, dict)
    assert isinstance(sc.controller.params, dict)  # kept as plain data
    assert sc.controller.params["mapping"] == "optimised" and sc.controller.type == ctrl
    assert not (tmp_path / "imported.marker").exists()
    assert "h8_colleague_mod" not in sys.modules


def test_analysis_of_the_example_log_where_its_controller_is_absent(tmp_path):
    """The example controller runs by path; its log then goes to ``figures`` and ``claims`` from
    a folder without the file: neither fails on the stored scenario's unknown controller."""
    src, away = tmp_path / "src", tmp_path / "away"
    src.mkdir()
    away.mkdir()
    for f in ("my_controller.py", "my_controller.yaml"):
        shutil.copy(ROOT / "examples" / f, src)
    log = src / "keeper.mcap"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    run = subprocess.run(
        [*REPLAY, "run", src / "my_controller.yaml", "--quiet", "-o", log],
        cwd=away,
        capture_output=True,
        text=True,
        timeout=180,
        env=env,
    )
    assert run.returncode == 0 and log.is_file(), run.stderr
    (src / "my_controller.py").unlink()
    for command in (["figures", log, "-o", away / "figs"], ["claims", log], ["info", log]):
        r = subprocess.run(
            [*REPLAY, *command], cwd=away, capture_output=True, text=True, timeout=180, env=env
        )
        out = r.stdout + r.stderr
        assert r.returncode == 0, out
        assert "Traceback" not in out
        assert "my_controller:GoalKeeper" not in out or "not imported" not in out, out
        assert "unknown controller" not in out, out
