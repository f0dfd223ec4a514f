"""Rerun reads our logs: ``rerun mcap convert`` turns a catch log into transforms, images, log
lines and the robot's URDF geometry, read back with rerun's own chunk reader."""

from __future__ import annotations

import shutil
import subprocess
import sys
from collections import Counter, defaultdict
from pathlib import Path

from rerun.chunk import RrdReader  # rerun-sdk: the test extra

from replay.foxglove.schemas import decode
from replay.log import LogReader
from replay.messages import TOPIC_LOG, TOPIC_TF
from replay.runner import Runner
from replay.scenario import load_scenario

from conftest import ROOT


def rerun_cli() -> str:
    local = Path(sys.executable).with_name("rerun")
    return str(local) if local.exists() else (shutil.which("rerun") or "rerun")


def test_rerun_converts_a_catch_log_into_transforms_images_and_the_robot(tmp_path):
    sc = load_scenario(ROOT / "scenarios" / "catch_optimised.yaml", ["timing.duration=0.05"])
    log = Runner(sc).run(tmp_path / "catch.mcap").path
    rrd = tmp_path / "catch.rrd"
    done = subprocess.run(
        [rerun_cli(), "mcap", "convert", str(log), "-o", str(rrd)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-2000:]

    rows: Counter = Counter()
    columns: dict[str, set] = defaultdict(set)
    children: set = set()
    for chunk in RrdReader(rrd).store().stream():
        batch = chunk.to_record_batch()
        names = set(batch.schema.names)
        path = chunk.entity_path
        columns[path] |= names
        if "Transform3D:child_frame" in names:
            rows[path, "Transform3D"] += chunk.num_rows
            for cell in batch.column("Transform3D:child_frame").to_pylist():
                children.update(cell or [])
        if "Image:buffer" in names:
            rows[path, "Image"] += chunk.num_rows
        if "TextLog:text" in names:
            rows[path, "TextLog"] += chunk.num_rows

    r = LogReader(log)
    n_tf = sum(len(decode(m.schema, m.data).transforms) for m in r.raw(TOPIC_TF))
    counts = r.topic_counts()
    assert rows[TOPIC_TF, "Transform3D"] == n_tf  # one row per transform
    assert {"wam_base", "wam_tool", "palm", "ball"} <= children
    for view in ("cam0", "cam1"):
        topic = f"/camera/stereo/{view}"
        assert rows[topic, "Image"] == counts[topic] == 50
    assert rows[TOPIC_LOG, "TextLog"] == counts[TOPIC_LOG]
    robot = [p for p in columns if "/visual_geometries/" in p]  # the URDF on /robot_description
    assert any("wam_link1" in p for p in robot), sorted(columns)[:20]
