"""The grasping figures (analysis/grasping/figures.py) and claims (analysis/grasping/claims.py) from
synthetic logs with the contract's topics (grasp_synthetic.py): they read what the log holds, and
each claim's status follows the numbers (a log that breaks a claim gets "differs")."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from grasp_synthetic import GRIP_X, LAG, PLANE_X, STANDOFF, write_grasp_log
from replay import registry
from replay.log import LogReader


def _rows(path) -> dict[str, object]:
    """The table's rows and the run's own (its "g: " dropped) by claim."""
    from analysis.grasping.claims import evaluate, per_run

    logs = {"g": LogReader(path)}
    table = {r.quantity: r for r in evaluate(logs)}
    table.update((r.quantity.removeprefix("g: "), r) for r in per_run(logs)["g"])
    return table


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("grasp_synthetic")
    return {
        "box": write_grasp_log(d / "box.mcap"),
        "ball_1khz": write_grasp_log(d / "ball.mcap", obj="ball", rate=1000, duration=1.2),
        "leads": write_grasp_log(d / "leads.mcap", lag=-0.01, duration=1.2),
        "slips": write_grasp_log(d / "slips.mcap", slip_at=1.0, duration=1.2),
    }


def test_analysis_is_registered_under_the_papers_key():
    assert registry.load("figures", "namiki1999").__module__ == "analysis.grasping.figures"
    assert registry.load("claims", "namiki1999").__module__ == "analysis.grasping.claims"


def test_phases_and_cycles_from_the_schedule(logs):
    from analysis.grasping.run import load_run

    run = load_run(LogReader(logs["box"]))
    assert [p.name for p in run.phases] == [
        "track",
        "reach",
        "hold",
        "release",
        "track",
        "reach",
        "hold",
    ]
    c = run.cycles()
    assert len(c) == 2 and c[0]["grasp"] is not None
    assert c[0]["reach"].t0 == pytest.approx(0.5) and c[0]["grasp"]["t"] == pytest.approx(0.8)


def test_figures_png_and_svg_and_the_same_log_gives_the_same_svg(logs, tmp_path):
    from analysis.grasping.figures import make_figures

    a = make_figures({"box": LogReader(logs["box"])}, tmp_path / "a")
    b = make_figures({"box": LogReader(logs["box"])}, tmp_path / "b")
    assert sorted(p.name for p in a) == [
        "box_fig9.png",
        "box_fig9.svg",
        "box_filmstrip.png",
        "box_filmstrip.svg",
    ]
    for pa, pb in zip(a, b):
        assert pa.stat().st_size > 5000
        if pa.suffix == ".svg":
            assert pa.read_bytes() == pb.read_bytes()


def test_filmstrip_frames_cover_the_first_cycle(logs):
    from analysis.grasping.figures import filmstrip_times
    from analysis.grasping.run import load_run

    times = filmstrip_times(load_run(LogReader(logs["box"])))
    ts = [t for t, _ in times]
    assert ts == sorted(ts) and ts[0] == 0.0 and 0.8 in ts and ts[-1] < 1.3
    assert [label for _, label in times][4] == "grasped"


def test_replay_figures_and_claims_commands(logs, tmp_path):
    from replay.cli import main

    r = CliRunner().invoke(main, ["figures", str(logs["box"]), "-o", str(tmp_path / "f")])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "f" / "synthetic_grasp_fig9.svg").is_file()  # named by the scenario
    r = CliRunner().invoke(main, ["claims", str(logs["box"])])
    assert r.exit_code == 0, r.output
    assert "High Speed Grasping" in r.output or "namiki1999" in r.output
    assert "stable grasping: held while the human moves the object" in r.output


def test_claims_follow_the_numbers(logs):
    box, ball = _rows(logs["box"]), _rows(logs["ball_1khz"])
    # 500 Hz synthetic loops are not the paper's 1 ms; the 1 kHz log's are
    assert box["cycle of every feedback loop (Fig. 4)"].status == "differs"
    assert ball["cycle of every feedback loop (Fig. 4)"].status == "consistent"
    assert ball["sensor-to-actuator latency of every loop"].status == "consistent"
    assert ball["cycle of every feedback loop (Fig. 4)"].kind == "configuration"
    t = box["tracking 0.0-0.5, reaching and grasping done at 0.8, read as seconds"]
    assert t.status == "reproduced"
    ms = box["the same times read as printed (ms)"]
    assert ms.status == "inconsistent"
    need = (GRIP_X - (PLANE_X - STANDOFF)) / 0.0003  # m/s, from the log's reach
    assert f"{abs(need):.0f} m/s" in ms.measured
    assert box["the preshape matches the shape (Figs. 5b, 8)"].status == "consistent"
    assert "circle" in ball["the preshape matches the shape (Figs. 5b, 8)"].measured
    assert box["the grasp holds while the human keeps moving the object"].status == "reproduced"
    rel = box["tracking error on the plane (Y, Z), releasing and tracking phases"]
    assert rel.status == "reproduced"
    lag = box["no prediction of the object's motion"]
    assert lag.status == "consistent" and lag.kind == "configuration"
    assert f"{1000 * LAG:.3g} ms" in ball["no prediction of the object's motion"].measured


def test_a_leading_hand_and_a_slip_break_their_claims(logs):
    leads, slips = _rows(logs["leads"]), _rows(logs["slips"])
    row = leads["no prediction of the object's motion"]
    assert row.status == "differs" and "-10 ms" in row.measured
    row = slips["the grasp holds while the human keeps moving the object"]
    assert row.status == "differs" and "slip at 1.000 s" in row.measured, row.measured
