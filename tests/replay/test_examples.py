"""The numbered examples/ run as a newcomer would run them (a subprocess each) and say what
they should."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _run(name: str, *args) -> str:
    r = subprocess.run(
        [sys.executable, str(EXAMPLES / name), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    return r.stdout


def test_examples_are_numbered_and_all_tested():
    names = sorted(p.name for p in EXAMPLES.glob("*.py"))
    scripts = [n for n in names if n[:2].isdigit()]
    assert scripts == [
        "01_run_a_scenario.py",
        "02_read_a_log.py",
        "03_write_a_plugin_plant.py",
        "04_python_api.py",  # (run by tests/replay/test_api.py)
        "05_evaluate_a_policy.py",  # (run by tests/replay/test_evaluate.py)
    ]
    # the modules that are no script: the controller examples/my_controller.yaml names by
    # file (type: my_controller:GoalKeeper; tests/replay/test_plugins_from_files.py) and the
    # policies `replay evaluate my_policy:catch` names (tests/replay/test_evaluate.py)
    assert sorted(set(names) - set(scripts)) == ["my_controller.py", "my_policy.py"]
    assert "my_controller:" in (EXAMPLES / "my_controller.yaml").read_text(encoding="utf-8")


def test_01_runs_a_scenario_from_python(tmp_path):
    out = _run("01_run_a_scenario.py", tmp_path)
    log = tmp_path / "stick_3step.mcap"
    assert log.is_file() and f"wrote {log}" in out
    assert "t_end = 0.300 s, stopped by duration" in out
    # 0.3 s is before the capture: the plant's verdict says why
    assert "outcome: success=False reason='not captured: the stick still moves" in out


def test_02_reads_a_log(tmp_path):
    out = _run("02_read_a_log.py")  # the stored golden log
    assert "scenario stick_3step" in out and "plant airtable" in out
    assert "/stick/state" in out and "event t = " in out and "outcome" in out
    # and a log the first example wrote
    _run("01_run_a_scenario.py", tmp_path)
    out = _run("02_read_a_log.py", tmp_path / "stick_3step.mcap")
    assert "t = 0.000 .. 0.300 s" in out


def test_03_writes_a_plugin_plant_that_reaches_its_target(tmp_path):
    out = _run("03_write_a_plugin_plant.py", tmp_path)
    assert (tmp_path / "cart.mcap").is_file()
    assert "'success': True" in out and "x = 0.000 -> 1.000 m" in out
