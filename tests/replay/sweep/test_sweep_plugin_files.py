"""A sweep of a scenario whose controller is a module:Class from a file: a fresh worker process
(as a Ray worker is: nothing forked from the planner) imports it again from where the planner
found it."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from replay import registry
from replay.scenario.loader import load_scenario, resolved_yaml

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"

WORKER = """
import json, sys
from replay.sweep.worker import run_variant
row = run_variant(json.loads(sys.stdin.read()))
print(json.dumps({k: row.get(k) for k in ("success", "reason", "stopped_by")}))
"""


def _in_a_fresh_process(task: dict, cwd: Path) -> dict:
    r = subprocess.run(
        [sys.executable, "-c", WORKER],
        input=json.dumps(task),
        capture_output=True,
        text=True,
        timeout=300,
        cwd=cwd,
    )
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_a_fresh_worker_imports_the_plugin_the_planner_imported(tmp_path):
    sc = load_scenario(EXAMPLES / "my_controller.yaml", sets=["timing.duration=0.05"])
    found = [p for p in registry.imported_plugins() if p[1] == "my_controller:GoalKeeper"]
    assert found == [("controller", "my_controller:GoalKeeper", str(EXAMPLES.resolve()))]
    task = {"key": "k", "index": 0, "resolved": resolved_yaml(sc), "error": "", "log": ""}
    task["cwd"] = str(tmp_path)  # not the plug-in's folder
    without = _in_a_fresh_process(task, tmp_path)
    assert without["success"] is False and "not imported" in without["reason"], without
    ran = _in_a_fresh_process({**task, "plugins": found}, tmp_path)
    assert ran["stopped_by"] == "duration" and "error" not in ran["reason"], ran
