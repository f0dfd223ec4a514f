"""Where the command line writes what: results on stdout; every user error one ``error:`` line
on stderr (exit 2); warnings, notes and progress on stderr, progress only on a terminal.
Also ``replay schema``, ``replay urdf`` and shell completion."""

from __future__ import annotations

import io
import json
import stat
import time

from click.testing import CliRunner

from replay.cli import main
from replay.console import REDRAW, RunProgress, bars_on


def invoke(*args, env=None):
    return CliRunner().invoke(
        main, [str(a) for a in args], catch_exceptions=False, env=env, prog_name="replay"
    )


def one_error(r) -> str:
    """The one ``error:`` line on stderr, nothing on stdout."""
    lines = [l for l in r.stderr.splitlines() if l.strip()]
    assert r.stdout == "", r.stdout
    assert len(lines) == 1 and lines[0].startswith("error: "), r.stderr
    assert "Traceback" not in r.stderr
    return lines[0]


def test_run_results_on_stdout_nothing_on_stderr(toy_yaml, tmp_path):
    out = tmp_path / "toy.mcap"
    r = invoke("run", toy_yaml, "-o", out, "--set", "timing.duration=0.2")
    assert r.exit_code == 0, r.output
    assert r.stderr == ""  # not a terminal: no progress bar
    assert r.stdout.splitlines()[0].startswith("toy: 0.200 s simulated")
    assert r.stdout.splitlines()[1] == f"log: {out}"
    r = invoke("run", toy_yaml, "-o", out, "--set", "timing.duration=0.2", "--quiet")
    assert r.exit_code == 0 and r.stdout == "" and r.stderr == ""
    r = invoke("info", out)
    assert r.exit_code == 0 and "topics:" in r.stdout and r.stderr == ""


def test_every_user_error_is_one_error_line_on_stderr(toy_yaml, tmp_path):
    junk = tmp_path / "junk.mcap"
    junk.write_text("not a log")
    for args, expected in (
        (["run"], "Missing argument 'SCENARIO'"),
        (["run", toy_yaml, "--bogus"], "No such option '--bogus'"),
        (["run", toy_yaml, "--seed", "x"], "'--seed'"),
        (["frobnicate"], "No such command 'frobnicate'"),
        (["run", tmp_path / "nope.yaml"], "no such scenario file"),
        (["run", toy_yaml, "--set", "timing.duration=-1"], "timing.duration"),
        (["info", junk], "not an MCAP log"),
        (["urdf", "stick_3step"], "Missing option '-o'"),
        (["urdf", "stick_3step", "-o", tmp_path / "x.urdf"], "has no URDF"),
        (["schema", "-o", toy_yaml], "will not write"),
        (["golden", "check", "no_such_golden"], "unknown golden log"),
    ):
        r = invoke(*args)
        assert r.exit_code == 2, (args, r.output)
        assert expected in one_error(r), (args, r.stderr)
    assert not (tmp_path / "x.urdf").exists()


def test_a_truncated_log_is_a_warning_on_stderr_and_results_on_stdout(toy_yaml, tmp_path):
    out = tmp_path / "toy.mcap"
    assert invoke("run", toy_yaml, "-o", out, "--quiet").exit_code == 0
    data = out.read_bytes()
    out.write_bytes(data[: len(data) * 9 // 10])
    r = invoke("info", out)
    assert r.exit_code == 0 and "topics:" in r.stdout
    assert r.stderr and all(l.startswith("warning: ") for l in r.stderr.splitlines())


def test_schema_to_stdout_and_to_a_file(tmp_path):
    r = invoke("schema")
    assert r.exit_code == 0 and r.stderr == ""
    schema = json.loads(r.stdout)
    assert schema["$schema"].startswith("http://json-schema.org/draft-07")
    assert (
        "airtable"
        in schema["definitions"]["scenario"]["properties"]["plant"]["properties"]["type"]["anyOf"][
            0
        ]["enum"]
    )
    out = tmp_path / "editor/scenario.schema.json"
    r = invoke("schema", "-o", out)
    assert r.exit_code == 0 and r.stdout == f"wrote {out}\n"
    assert json.loads(out.read_text()) == schema
    assert stat.S_IMODE(out.stat().st_mode) == 0o644
    assert invoke("schema", "-o", out).exit_code == 0  # an earlier schema may be replaced
    notes = tmp_path / "notes.txt"
    notes.write_text("mine")
    assert "will not overwrite" in one_error(invoke("schema", "-o", notes))
    assert notes.read_text() == "mine"


def test_urdf_of_the_arm_is_written_readable_by_all(project_root, tmp_path):
    import xml.etree.ElementTree as ET

    out = tmp_path / "wam.urdf"
    r = invoke("urdf", "catch_optimised", "-o", out)
    assert r.exit_code == 0, r.output
    assert r.stdout == f"wrote {out}\n" and r.stderr == ""
    assert stat.S_IMODE(out.stat().st_mode) == 0o644
    robot = ET.fromstring(out.read_text())
    assert robot.tag == "robot"
    joints = {j.get("name"): j.get("type") for j in robot.iter("joint")}
    assert sum(t == "revolute" for t in joints.values()) >= 3  # the arm's active joints
    # the same robot the plant loads into PyBullet
    from plants.arm_rig.settings import resolve
    from replay.scenario import load_scenario

    sc = load_scenario("scenarios/catch_optimised.yaml")
    assert out.read_text() == resolve(sc.plant.params).arm_model().urdf
    # another scenario, another robot (the grasping rig: a 7-joint arm, a 14-joint hand)
    r = invoke("urdf", "grasp_hexahedron", "-o", tmp_path / "grasp.urdf")
    assert r.exit_code == 0, r.output
    assert (tmp_path / "grasp.urdf").read_text() != out.read_text()
    notes = tmp_path / "notes.txt"
    notes.write_text("mine")
    assert "will not overwrite" in one_error(invoke("urdf", "catch_optimised", "-o", notes))


def test_shell_completion_offers_shipped_scenarios_and_goldens():
    env = {
        "_REPLAY_COMPLETE": "bash_complete",
        "COMP_WORDS": "replay run stick_3",
        "COMP_CWORD": "2",
    }
    r = invoke(env=env)
    items = r.stdout.split()
    assert "plain,stick_3step" in items and "plain,stick_3step_mu0" in items
    assert "file,stick_3" in items  # and files
    assert not any("catch" in i for i in items)
    env = {
        "_REPLAY_COMPLETE": "bash_complete",
        "COMP_WORDS": "replay golden check ",
        "COMP_CWORD": "3",
    }
    assert "plain,catch_optimised" in invoke(env=env).stdout.split()
    env = {
        "_REPLAY_COMPLETE": "bash_complete",
        "COMP_WORDS": "replay ablate catch_",
        "COMP_CWORD": "2",
    }
    items = invoke(env=env).stdout.split()
    assert items and all(i.startswith("plain,catch_") for i in items)
    r = invoke(env={"_REPLAY_COMPLETE": "bash_source"})
    assert "_replay_completion" in r.stdout and "complete " in r.stdout


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_only_on_a_terminal_and_not_quiet():
    assert bars_on(False, _Terminal()) and not bars_on(True, _Terminal())
    assert not bars_on(False, io.StringIO())
    off = RunProgress("x", False)
    off(0.5, 1.0)
    off.done()
    assert off.redraws == 0


def test_progress_bar_has_rate_and_eta_and_redraws_at_most_10_times_a_second():
    stream = _Terminal()
    p = RunProgress("stick_3step", True, stream=stream)
    t0 = time.monotonic()
    calls = 0
    while time.monotonic() - t0 < 0.35:  # a runner calling back as fast as it can
        calls += 1
        p(min(2.0, calls * 1e-4), 2.0)
    elapsed = time.monotonic() - t0
    p.done()
    assert calls > 1000
    assert 2 <= p.redraws <= elapsed / REDRAW + 2, (p.redraws, elapsed)
    text = stream.getvalue()
    assert "stick_3step:" in text and "x real time" in text and "/2.000 s" in text
    assert "<00:" in text  # elapsed<remaining (ETA)
