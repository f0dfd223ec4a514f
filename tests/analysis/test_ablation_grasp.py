"""The grasp thesis's verdict and the component ablation's sentence (analysis/grasping/ablations.py),
computed from rate tables: synthetic ones whose answer is known, and the stored ones."""

from __future__ import annotations

import csv

import pytest

from analysis.grasping import ablations as ag
from replay.resources import data_path

PERIODS = (1, 2, 5, 10, 15, 20, 33)


def table(rates: dict[str, dict[int, int]], n: int = 20) -> list[dict]:
    """Rows of a grasp_loops table: ``rates[motion][period]`` runs of ``n`` grasped."""
    rows = []
    for motion, by_period in rates.items():
        for period, k in by_period.items():
            for seed in range(n):
                ok = seed < k
                rows.append(
                    {
                        "loop_period_ms": str(period),
                        "motion": motion,
                        "seed": str(seed),
                        "success": str(ok),
                        "m.grasps": "1" if ok else "0",
                        "m.tracking_error_rms": "0.005",
                    }
                )
    return rows


def flat(k: int) -> dict[int, int]:
    return {p: k for p in PERIODS}


def test_ties_at_every_period_do_not_hold():
    said = ag.thesis({"grasp_loops": table({"0.1": flat(20), "0.4": flat(17)})})
    assert said["verdict"].startswith("does not hold")
    assert "every period up to 33 ms tie with it" in said["verdict"]
    assert said["figure"] == "grasp_loops"
    assert "1 ms 17/20 [" in said["numbers"]


def test_losing_grasps_only_at_the_faster_motion_holds_only_when():
    slow = {p: (18 if p < 10 else 3) for p in PERIODS}
    said = ag.thesis(table({"0.1": flat(20), "0.4": slow}))
    assert said["verdict"].startswith("holds only when the object moves at 0.4 m/s RMS")
    assert "slowed to 10 ms or more" in said["verdict"]
    assert "loops of up to 5 ms tie with it" in said["verdict"]
    assert "at 0.1 m/s RMS every period up to 33 ms ties" in said["verdict"]


def test_losing_grasps_at_2_ms_everywhere_holds():
    drop = {p: (20 if p == 1 else 2) for p in PERIODS}
    said = ag.thesis(table({"0.1": drop, "0.4": drop}))
    assert said["verdict"].startswith("holds:")


def test_failing_at_1_ms_does_not_hold():
    said = ag.thesis(table({"0.4": flat(5)}))
    assert said["verdict"].startswith("does not hold: the 1 ms loops themselves")


def test_thesis_reads_rows_and_a_path(tmp_path):
    rows = table({"0.1": flat(20), "0.4": {p: (18 if p < 10 else 3) for p in PERIODS}})
    path = tmp_path / "grasp_loops.csv"
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    assert ag.thesis(rows)["verdict"] == ag.thesis(path)["verdict"]
    assert ag.thesis({})["verdict"] == "not run"


def test_components_needed_only_outside_the_intervals():
    rows = []
    for name, k in (("full system", 19), ("no tracking", 2), ("no partition S", 16)):
        for seed in range(20):
            rows.append(
                {"component": name, "success": str(seed < k), "m.grasps": "1" if seed < k else "0"}
            )
    text = ag.summary_components(rows)
    assert "Full system 19/20" in text
    assert "no tracking: 2/20" in text and "no tracking: 2/20 [" in text
    assert text.count("needed") == 2  # "no tracking ... needed"; "... (not shown needed)"
    assert "no partition S: 16/20 [" in text and "a tie" in text
    said = ag.thesis({"grasp_loops": table({"0.4": flat(18)}), "grasp_components": rows})
    assert said["numbers"].endswith(text)


@pytest.mark.parametrize("name", ["grasp_loops", "grasp_components"])
def test_stored_tables_give_a_sentence(name):
    from replay.sweep.table import read_table

    path = data_path("ablations", f"{name}.csv")
    assert path.is_file(), f"no stored {name} table (replay ablate {name} --store)"
    rows = read_table(path)
    assert rows and (ag.MOTION in rows[0] or ag.COMPONENT in rows[0]), f"{name}: an old table"
    if name == "grasp_loops":
        said = ag.thesis({name: rows})
        assert said["verdict"].split(":")[0].split(" only")[0] in ("holds", "does not hold")
        assert all(f"{p:g} ms" in said["numbers"] for p in PERIODS)
    else:
        assert ag.summary_components(rows).startswith("Full system")
