"""Resource limits on a scenario (issue #36, items 6-8 and 11): every size that decides how much
memory or time a run spends is refused before any work, as one line naming the field, the limit
and its environment variable, by `replay validate` (with or without --static) as by `replay run`;
a scenario's text is bounded before it is parsed; `extends:` reads only scenario files and never
quotes another file's text."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import time

import pytest
from click.testing import CliRunner

from replay.cli import main
from replay.scenario import ScenarioError, load_scenario, scenario_from_text
from replay.scenario.log_size import projected_log_bytes

GRASP = "grasp_hexahedron"
HUMAN = "plant.params.human_components"
CHIP_W, CHIP_H = "sensors.chip.params.width", "sensors.chip.params.height"


def invoke(*args, env=None):
    return CliRunner().invoke(main, [str(a) for a in args], env=env, catch_exceptions=False)


def _one_error_line(output: str) -> str:
    lines = [line for line in output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), output
    assert "Traceback" not in output
    return lines[0]


def _cap_memory():  # a child that would allocate without bound fails fast instead
    resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))


def _replay(*args, env=None, timeout=60):
    """The CLI as a subprocess under a 3 GiB address-space cap: (exit code, stderr, seconds)."""
    t0 = time.monotonic()
    r = subprocess.run(
        [sys.executable, "-m", "replay.cli", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, **(env or {})},
        preexec_fn=_cap_memory,
    )
    return r.returncode, r.stderr, time.monotonic() - t0


# -- sizes of plug-in parameters ------------------------------------------------------------


@pytest.mark.parametrize("command", [("validate",), ("validate", "--static")])
def test_human_table_is_refused_before_it_is_built(project_root, command):
    """The reproducer: human_components=10^9 grew ~125 MB/s in validate before any check."""
    code, err, seconds = _replay(*command, GRASP, "--set", f"{HUMAN}=1000000000")
    assert code == 2, err
    line = _one_error_line(err)
    assert HUMAN in line and "1,000,000,000 rows" in line and "100,000" in line
    assert "REPLAY_LIMIT_TABLE_ROWS" in line and "MemoryError" not in err
    assert seconds < 20


@pytest.mark.parametrize(
    "sets, field, limit",
    [
        ([f"{HUMAN}=100001"], HUMAN, "REPLAY_LIMIT_TABLE_ROWS"),
        (["tasks.schedule.params.cycles=2000000000"], "cycles", "REPLAY_LIMIT_TABLE_ROWS"),
        ([f"{CHIP_W}=100000", f"{CHIP_H}=100000"], CHIP_W, "REPLAY_LIMIT_CAMERA_PIXELS"),
        ([f"{CHIP_W}=8388609", f"{CHIP_H}=2"], CHIP_W, "REPLAY_LIMIT_CAMERA_PIXELS"),
    ],
)
@pytest.mark.parametrize("static", [True, False])
def test_sizes_over_a_limit_are_one_line(project_root, sets, field, limit, static):
    args = ["validate", *(["--static"] if static else []), GRASP]
    for s in sets:
        args += ["--set", s]
    r = invoke(*args)
    assert r.exit_code == 2
    line = _one_error_line(r.output)
    assert field in line and limit in line and "over the limit" in line


def test_a_plan_search_too_fine_is_refused_not_a_run_dying(project_root, tmp_path):
    """search_step=1e-12 validated, then the run died allocating 2.8 TiB of arrival times and
    left a .part; now validate and run refuse it at the field."""
    sets = ["--set", "controller.params.search_step=1e-12"]
    for args in (
        ("validate", "predictive_catch"),
        ("run", "predictive_catch", "-o", tmp_path / "p.mcap"),
    ):
        r = invoke(*args, *sets)
        assert r.exit_code == 2
        line = _one_error_line(r.output)
        assert "controller.params.search_step" in line and "REPLAY_LIMIT_TABLE_ROWS" in line
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "scenario, sets",
    [
        (
            "catch_optimised",
            ["sensors.stereo.params.width=2048", "sensors.stereo.params.height=2048"],
        ),
        ("stick_3step", ["sensors.camera.params.width=4096", "sensors.camera.params.height=4096"]),
    ],
)
def test_every_camera_counts_its_pixels(project_root, monkeypatch, scenario, sets):
    monkeypatch.setenv("REPLAY_LIMIT_CAMERA_PIXELS", "1000000")  # under 2048 x 2048
    with pytest.raises(ScenarioError) as info:
        load_scenario(f"scenarios/{scenario}.yaml", sets=sets)
    msg = str(info.value)
    assert "REPLAY_LIMIT_CAMERA_PIXELS" in msg and sets[0].split("=")[0] in msg


def test_a_raised_limit_lets_it_pass_and_a_bad_one_is_one_line(project_root):
    sets = ["--set", f"{HUMAN}=200000"]
    assert invoke("validate", "--static", GRASP, *sets).exit_code == 2
    r = invoke("validate", "--static", GRASP, *sets, env={"REPLAY_LIMIT_TABLE_ROWS": "300000"})
    assert r.exit_code == 0 and "ok:" in r.output
    for bad in ("lots", "-5", "0", "1e9"):
        r = invoke("validate", "--static", GRASP, *sets, env={"REPLAY_LIMIT_TABLE_ROWS": bad})
        assert r.exit_code == 2
        line = _one_error_line(r.output)
        assert "REPLAY_LIMIT_TABLE_ROWS" in line and "positive integer" in line


def test_a_refused_run_leaves_no_log(project_root, tmp_path):
    """The reproducer of item 7: the 100000 x 100000 chip validated, then the run died with a
    MemoryError and left a .part. Now both refuse it before anything is written."""
    out = tmp_path / "logs" / "chip.mcap"
    sets = ["--set", f"{CHIP_W}=100000", "--set", f"{CHIP_H}=100000"]
    code, err, _ = _replay("run", GRASP, "-q", "-o", out, *sets)
    assert code == 2, err
    line = _one_error_line(err)
    assert CHIP_W in line and "10,000,000,000 pixels" in line and "MemoryError" not in err
    assert list(tmp_path.rglob("*")) == []


# -- a run's projected log size ---------------------------------------------------------------


def test_projected_log_size_is_refused_before_the_run(project_root, tmp_path):
    """2000 x 2000 images at 1 kHz for 10 s: 40 GB of pixels, refused by validate --static,
    validate and run alike, naming timing.duration, the sensor and the limit."""
    sets = ["--set", f"{CHIP_W}=2000", "--set", f"{CHIP_H}=2000", "--set", "timing.duration=10"]
    out = tmp_path / "big.mcap"
    for args in (("validate", "--static", GRASP), ("validate", GRASP), ("run", GRASP, "-o", out)):
        r = invoke(*args, *sets)
        assert r.exit_code == 2
        line = _one_error_line(r.output)
        assert "timing.duration" in line and "sensors.chip" in line
        assert "REPLAY_LIMIT_LOG_BYTES" in line and "2000 x 2000" in line
    assert list(tmp_path.iterdir()) == []
    r = invoke("validate", "--static", GRASP, *sets, env={"REPLAY_LIMIT_LOG_BYTES": "10**11"})
    assert r.exit_code == 2 and "REPLAY_LIMIT_LOG_BYTES" in r.output  # not a number
    r = invoke(
        "validate", "--static", GRASP, *sets, env={"REPLAY_LIMIT_LOG_BYTES": "100_000_000_000"}
    )
    assert r.exit_code == 0, r.output


def test_projected_log_size_without_images(toy_yaml):
    """No camera logs images: the state at 100 kHz for 600 s is over the limit too, at the
    duration's line."""
    text = toy_yaml.read_text().replace(
        "physics_rate: 1000, duration: 1.0", "physics_rate: 100000, duration: 600"
    )
    toy_yaml.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(toy_yaml)
    msg = str(info.value)
    assert "toy.yaml:5:" in msg and "timing.duration" in msg and "the plant's state" in msg
    assert "REPLAY_LIMIT_LOG_BYTES" in msg


def test_shipped_scenarios_are_far_under_the_log_limit(project_root):
    for name in ("catch_optimised", "grasp_cycle", "stick_3step_width10_long"):
        size, _ = projected_log_bytes(load_scenario(f"scenarios/{name}.yaml"))
        assert 1e6 < size < 1e8


# -- a scenario's text ------------------------------------------------------------------------


def _stick_text(project_root) -> str:
    return (project_root / "scenarios" / "stick_3step.yaml").read_text()


def test_a_huge_stored_scenario_is_refused_before_parsing(project_root):
    """The reproducer of item 8: a log's stored scenario with a 30 MB comment kept `claims` busy
    past 90 s; now refused at once, naming the limit."""
    text = "#" + "x" * 30_000_000 + "\n" + _stick_text(project_root)
    t0 = time.monotonic()
    with pytest.raises(ScenarioError) as info:
        scenario_from_text(text, name="run.mcap:/scenario")
    assert time.monotonic() - t0 < 2.0
    msg = str(info.value)
    assert msg.startswith("run.mcap:/scenario: ") and "\n" not in msg
    assert "30,0" in msg and "REPLAY_LIMIT_SCENARIO_BYTES" in msg


def test_multibyte_text_counts_its_bytes(project_root, monkeypatch):
    monkeypatch.setenv("REPLAY_LIMIT_SCENARIO_BYTES", "20000")
    text = "# " + "\u00e9" * 9_000 + "\n" + _stick_text(project_root)  # < 20000 characters
    assert len(text) < 20_000 < len(text.encode())
    with pytest.raises(ScenarioError, match="REPLAY_LIMIT_SCENARIO_BYTES"):
        scenario_from_text(text)


def test_a_raised_text_limit_parses_it(project_root, monkeypatch):
    text = "#" + "x" * 1_100_000 + "\n" + _stick_text(project_root)
    with pytest.raises(ScenarioError, match="over the limit of 1,000,000"):
        scenario_from_text(text)
    monkeypatch.setenv("REPLAY_LIMIT_SCENARIO_BYTES", "2000000")
    assert scenario_from_text(text).name == "stick_3step"


def test_a_big_file_and_a_big_set_value_are_refused(project_root, tmp_path):
    big = tmp_path / "big.yaml"
    big.write_text("#" + "x" * 1_000_000 + "\n" + _stick_text(project_root))
    r = invoke("validate", "--static", big)
    line = _one_error_line(r.output)
    assert r.exit_code == 2 and "big.yaml" in line and "REPLAY_LIMIT_SCENARIO_BYTES" in line
    r = invoke("validate", "--static", "stick_3step", "--set", "notes=" + "y" * 1_000_001)
    line = _one_error_line(r.output)
    assert r.exit_code == 2 and "<--set notes>" in line and "REPLAY_LIMIT_SCENARIO_BYTES" in line


@pytest.mark.parametrize(
    "text",
    [
        "a: " + "[" * 20_000 + "]" * 20_000,
        "a: " + "{b: " * 20_000 + "}" * 20_000,
        "".join(" " * i + f"k{i}:\n" for i in range(1_200)),  # (under the size limit)
        "- " * 20_000 + "x",
    ],
)
def test_deep_nesting_is_one_line_not_a_recursion_error(text):
    with pytest.raises(ScenarioError) as info:
        scenario_from_text(text, name="deep.mcap:/scenario")
    assert "nested deeper than" in str(info.value) and "\n" not in str(info.value)


# -- extends ------------------------------------------------------------------------------------

SECRET = "root:*:20228:0:99999:7:::\ndaemon:*:20228:0:99999:7:::\n"


def _extends(tmp_path, value: str) -> str:
    child = tmp_path / "child.yaml"
    child.write_text(f"extends: {value}\nname: x\n")
    r = invoke("validate", "--static", child)
    assert r.exit_code == 2
    return _one_error_line(r.output)


@pytest.mark.parametrize("name", ["shadow", "secret.txt", "passwd.conf"])
def test_extends_refuses_a_file_that_is_not_yaml(tmp_path, name):
    secret = tmp_path / name
    secret.write_text(SECRET)
    for value in (str(secret), f"./{name}"):
        line = _extends(tmp_path, value)
        assert (
            "extends" in line and ".yaml" in line and "20228" not in line and "daemon" not in line
        )


def test_extends_etc_shadow_quotes_nothing(tmp_path):
    """The reproducer of item 11 (answered with the first line of /etc/shadow)."""
    for value in ("/etc/shadow", "/etc/passwd", "/etc/hostname", "/proc/self/environ"):
        line = _extends(tmp_path, value)
        assert "expected a shipped scenario's name or a .yaml file" in line
        assert "root:" not in line and ":0:" not in line


@pytest.mark.parametrize("kind", ["fifo", "folder"])
def test_extends_of_a_fifo_or_a_folder_named_yaml_is_one_line_and_reads_nothing(tmp_path, kind):
    """A FIFO named secret.yaml would block a reader forever; a folder cannot be read: both
    are 'no such scenario file', and the FIFO is never opened (no writer is waiting on it)."""
    target = tmp_path / "secret.yaml"
    if kind == "fifo":
        os.mkfifo(target)
    else:
        target.mkdir()
    line = _extends(tmp_path, "secret.yaml")
    assert "no such scenario file 'secret.yaml'" in line


@pytest.mark.parametrize("link", ["secret.yaml", "secret.yml"])
def test_extends_refuses_a_yaml_link_to_another_file(tmp_path, link):
    (tmp_path / "shadow").write_text(SECRET)
    (tmp_path / link).symlink_to(tmp_path / "shadow")
    for value in (link, link.rsplit(".", 1)[0] if link.endswith(".yaml") else link):
        line = _extends(tmp_path, value)
        assert "is not a .yaml file" in line and "20228" not in line


@pytest.mark.parametrize(
    "content, kind",
    [
        (SECRET, "not a scenario"),  # a mapping whose key is the first line
        ("password: hunter2\ntoken: s3cr3t\n", "not a scenario"),
        ("hunter2\n", "got a single value"),
        ("- hunter2\n- s3cr3t\n", "got a list"),
        ("key: [hunter2\n", "not valid YAML"),
        ("\u00e9hunter2".encode("latin-1"), "not UTF-8"),
        (bytes(range(256)), "not UTF-8"),
    ],
)
def test_extends_of_a_non_scenario_yaml_names_the_file_not_its_text(tmp_path, content, kind):
    base = tmp_path / "base.yaml"
    if isinstance(content, bytes):
        base.write_bytes(content)
    else:
        base.write_text(content)
    line = _extends(tmp_path, "base.yaml")
    assert "base.yaml" in line and kind in line
    for word in ("20228", "daemon", "hunter2", "s3cr3t", "password", "token"):
        assert word not in line


def test_extends_of_scenarios_still_works(project_root, tmp_path):
    (tmp_path / "base.yaml").write_text((project_root / "scenarios/stick_3step.yaml").read_text())
    for value in (
        "stick_3step",
        "stick_3step.yaml",
        "base",
        "base.yaml",
        str(tmp_path / "base.yaml"),
    ):
        child = tmp_path / "child.yaml"
        child.write_text(f"extends: {value}\nname: child\n")
        sc = load_scenario(child)
        assert sc.name == "child" and sc.plant.type == "airtable"


def test_an_unknown_field_that_is_no_name_is_not_quoted(tmp_path):
    p = tmp_path / "s.yaml"
    p.write_text(SECRET)
    r = invoke("validate", "--static", p)
    line = _one_error_line(r.output)
    assert "unknown field (not a name)" in line and "20228" not in line and "s.yaml:1:1" in line
