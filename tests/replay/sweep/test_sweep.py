"""replay sweep: spec parsing, one clear line for bad input, the table from both executors,
reruns that skip, resumed sweeps, and failing variants as rows."""

from __future__ import annotations

import importlib.util
import time

import pytest
from click.testing import CliRunner

from replay.cli import main
from replay.sweep.engine import run_sweep
from replay.sweep.spec import SweepSpecError, from_options, parse_grid
from replay.sweep.table import read_table
from replay.sweep.variants import expand

STICK = "scenarios/stick_3step.yaml"
SHORT = ["timing.duration=0.33"]  # s: just past the first collision (t = 0.31 s)
FRICTION = "plant.params.stick.friction"
# columns that are the same whatever ran the variant (not timings, not local paths)
SAME = ("index", "key", FRICTION, "seed", "success", "reason", "stopped_by", "t_end")


def test_grid_values_are_yaml_and_lists_stay_whole():
    a = parse_grid("plant.params.x=1, 2.5e-3 ,[1, 2],true,abc")
    assert a.name == "plant.params.x"
    assert a.values == [1, 2.5e-3, [1, 2], True, "abc"]
    # YAML 1.1 reads 1:30 as 90 (base 60): kept as written, as --set keeps it
    assert parse_grid("x=1:30,0:0:1").values == ["1:30", "0:0:1"]


def test_random_draws_are_seeded_and_in_range():
    spec = from_options([], ["a.b=0.5:1.5", "c=1:3"], 20)
    p1, p2 = spec.points(7), spec.points(7)
    assert p1 == p2 and len(p1) == 20
    assert all(0.5 <= p["a.b"] <= 1.5 and p["c"] in (1, 2, 3) for p in p1)
    assert p1 != spec.points(8)


def test_grid_times_random_is_the_product():
    spec = from_options(["x=1,2,3", "y=a,b"], ["z=0:1"], 2)
    pts = spec.points(0)
    assert len(pts) == 12
    assert {(p["x"], p["y"]) for p in pts} == {(x, y) for x in (1, 2, 3) for y in "ab"}


@pytest.mark.parametrize(
    "grid, randoms, n, words",
    [
        (["friction"], [], None, "key.path=a,b,c"),
        (["a..b=1,2"], [], None, "bad key path"),
        (["a.b="], [], None, "comma-separated"),
        (["a.b=1,,2"], [], None, "comma-separated"),
        (["a.b=1,1"], [], None, "twice"),
        (["a.b=[1,2"], [], None, "not valid YAML"),
        ([], ["a.b=1"], None, "lo:hi"),
        ([], ["a.b=x:2"], None, "expected a number"),
        ([], ["a.b=0:1:2"], None, "lo:hi"),  # not [0, 62] by YAML 1.1's base 60
        ([], ["a.b=0:1:2:3"], None, "lo:hi"),
        ([], ["a.b=2:1"], None, "lo < hi"),
        ([], ["a.b=0:1"], 0, "at least 1"),
        (["a.b=1,2"], [], 3, "--random"),
        (["a.b=1,2"], ["a.b=0:1"], None, "varied twice"),
    ],
)
def test_bad_specs_say_what_is_wrong(grid, randoms, n, words):
    with pytest.raises(SweepSpecError, match=words.replace("[", r"\[")):
        from_options(grid, randoms, n)


@pytest.mark.parametrize(
    "args, words",
    [
        (["--grid", "plant.params.stick.friction"], "--grid expects key.path=a,b,c"),
        (["--grid", "plant.params.stick.fricton=0,1"], "no field 'fricton'"),
        (["--random", "plant.params.stick.friction=1:0"], "lo < hi"),
        ([], "nothing to vary"),
    ],
)
def test_cli_bad_grid_is_one_line_and_exit_2(project_root, tmp_path, args, words):
    r = CliRunner().invoke(main, ["sweep", STICK, "-o", str(tmp_path), *args])
    assert r.exit_code == 2, r.output
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and words in lines[0], r.output
    assert not (tmp_path / "table.csv").exists()


def _friction(values, seed=0):
    spec = from_options([f"{FRICTION}=" + ",".join(values)], [], None)
    return expand(STICK, spec, seed, sets=SHORT, version="test")


def test_stick_friction_grid_local_then_ray_same_table(project_root, tmp_path):
    assert importlib.util.find_spec("ray") is not None, (
        "the test extra installs paper-replay[cluster] (Ray)"
    )
    local, ray_dir = tmp_path / "local", tmp_path / "ray"
    # an interrupted sweep: two of the three variants done ...
    first = run_sweep(_friction(["0.0", "1.0"]), local, workers=2, progress=False)
    assert (first.ran, first.skipped) == (2, 0)
    # ... the full sweep resumes: only the missing one runs
    full = run_sweep(_friction(["0.0", "0.5", "1.0"]), local, workers=2, progress=False)
    assert (full.ran, full.skipped, full.total) == (1, 2, 3)
    rows = read_table(local / "table.csv")
    assert [r[FRICTION] for r in rows] == ["0.0", "0.5", "1.0"]
    # cut after the first collision: each row carries the outcome, not captured and why
    assert all(r["e.collision"] == "1" and r["success"] == "False" for r in rows), rows
    assert all("not captured" in r["reason"] for r in rows), rows
    assert len({r["key"] for r in rows}) == 3
    assert all(r["log"].endswith(".mcap") for r in rows)
    # a rerun runs nothing
    again = run_sweep(_friction(["0.0", "0.5", "1.0"]), local, workers=2, progress=False)
    assert (again.ran, again.skipped) == (0, 3)
    # Ray: a private local instance on 127.0.0.1 with 2 CPUs, shut down at the end
    t0 = time.perf_counter()
    by_ray = run_sweep(
        _friction(["0.0", "0.5", "1.0"]),
        ray_dir,
        workers=2,
        executor="ray",
        keep_logs=False,
        progress=False,
    )
    from replay.sweep import executors

    print(
        f"ray sweep of 3 variants: {time.perf_counter() - t0:.1f} s wall, of which ray.init "
        f"{executors.last_ray_init:.1f} s"
    )
    assert by_ray.ran == 3
    ray_rows = read_table(ray_dir / "table.csv")
    assert [{k: r[k] for k in SAME} for r in ray_rows] == [{k: r[k] for k in SAME} for r in rows]
    metrics = sorted(k for k in rows[0] if k[:2] in ("m.", "e."))
    assert [[r[k] for k in metrics] for r in ray_rows] == [[r[k] for k in metrics] for r in rows]
    import ray

    assert not ray.is_initialized()


def test_failing_variants_are_rows_and_the_sweep_goes_on(toy_yaml, tmp_path):
    spec = from_options(["plant.params.blow_up_at=-1,0.3", "plant.params.mass=2,-1"], [], None)
    variants = expand(toy_yaml, spec, 0, version="test")
    summary = run_sweep(variants, tmp_path, workers=2, keep_logs=False, progress=False)
    assert (summary.total, summary.ran) == (4, 4)
    rows = {
        (r["plant.params.blow_up_at"], r["plant.params.mass"]): r
        for r in read_table(tmp_path / "table.csv")
    }
    assert rows[("-1", "2")]["success"] == "True"
    assert rows[("0.3", "2")]["success"] == "False"
    assert "non-finite" in rows[("0.3", "2")]["reason"]
    for blow in ("-1", "0.3"):
        bad = rows[(blow, "-1")]
        assert bad["success"] == "False" and bad["reason"].startswith("invalid:")
        assert "plant.params.mass" in bad["reason"]
    assert summary.ok == 1 and summary.failed == 3
    # a rerun skips them all; --retry-failed runs again those whose reason is an error (the NaN)
    # or invalid parameters, not the success
    assert run_sweep(variants, tmp_path, workers=2, keep_logs=False, progress=False).ran == 0
    retry = run_sweep(
        variants, tmp_path, workers=2, keep_logs=False, progress=False, retry_failed=True
    )
    assert (retry.ran, retry.skipped) == (3, 1)


def test_an_exception_in_a_plugin_is_a_row(toy_yaml, tmp_path, monkeypatch):
    import toy_plugins

    def broken(self, t, measurements):
        raise RuntimeError("controller exploded")

    monkeypatch.setattr(toy_plugins.ToyController, "update", broken)
    spec = from_options(["plant.params.mass=1,2"], [], None)
    summary = run_sweep(
        expand(toy_yaml, spec, 0, version="test"),
        tmp_path,
        workers=1,
        keep_logs=False,
        progress=False,
    )
    rows = read_table(tmp_path / "table.csv")
    assert summary.ran == 2 and len(rows) == 2
    assert all(r["success"] == "False" and "controller exploded" in r["reason"] for r in rows)


def test_cli_sweep_prints_one_summary_line(toy_yaml, tmp_path):
    r = CliRunner().invoke(
        main,
        [
            "sweep",
            str(toy_yaml),
            "--grid",
            "plant.params.mass=1,2",
            "-o",
            str(tmp_path),
            "--workers",
            "2",
            "--no-logs",
            "-q",
        ],
    )
    assert r.exit_code == 0, r.output
    assert r.output.startswith("sweep: 2 variants: 2 ran, 0 skipped")
    assert "variants/s" in r.output and len(read_table(tmp_path / "table.csv")) == 2


def test_the_key_follows_scenario_seed_and_code(project_root):
    spec = from_options([f"{FRICTION}=0.0,1.0"], [], None)
    a = [v.key for v in expand(STICK, spec, 0, sets=SHORT, version="v1")]
    assert a == [v.key for v in expand(STICK, spec, 0, sets=SHORT, version="v1")]
    assert set(a).isdisjoint(v.key for v in expand(STICK, spec, 1, sets=SHORT, version="v1"))
    assert set(a).isdisjoint(v.key for v in expand(STICK, spec, 0, sets=SHORT, version="v2"))
    assert set(a).isdisjoint(v.key for v in expand(STICK, spec, 0, version="v1"))


def test_seed_and_scenario_axes(toy_yaml, tmp_path):
    other = tmp_path / "toy_heavy.yaml"
    other.write_text(
        toy_yaml.read_text()
        .replace("name: toy", "name: toy_heavy")
        .replace("mass: 2.0", "mass: 5.0")
    )
    spec = from_options([f"scenario={toy_yaml},{other}", "seed=1,2"], [], None)
    variants = expand(toy_yaml, spec, 0, version="test")
    assert [(v.name, v.seed) for v in variants] == [
        ("toy", 1),
        ("toy", 2),
        ("toy_heavy", 1),
        ("toy_heavy", 2),
    ]
    run_sweep(variants, tmp_path / "out", workers=2, keep_logs=False, progress=False)
    with (tmp_path / "out" / "table.csv").open() as f:
        header = f.readline().strip().split(",")
    assert header.count("seed") == 1 and "scenario" in header
    rows = read_table(tmp_path / "out" / "table.csv")
    assert [(r["scenario"], r["seed"]) for r in rows] == [
        (str(toy_yaml), "1"),
        (str(toy_yaml), "2"),
        (str(other), "1"),
        (str(other), "2"),
    ]


def test_rows_of_another_code_version_are_set_aside(toy_yaml, tmp_path):
    spec = from_options(["plant.params.mass=1,2"], [], None)
    run_sweep(
        expand(toy_yaml, spec, 0, version="v1"),
        tmp_path,
        workers=2,
        keep_logs=False,
        progress=False,
    )
    keys_v1 = {r["key"] for r in read_table(tmp_path / "table.csv")}
    s = run_sweep(
        expand(toy_yaml, spec, 0, version="v2"),
        tmp_path,
        workers=2,
        keep_logs=False,
        progress=False,
    )
    assert (s.ran, s.stale) == (2, 2)
    assert {r["key"] for r in read_table(tmp_path / "table.stale.csv")} == keys_v1
    assert not keys_v1 & {r["key"] for r in read_table(tmp_path / "table.csv")}


def test_the_physics_engine_is_an_axis_like_any_field(project_root, tmp_path):
    """plant.params.engine is left out of a resolved scenario while empty (PyBullet's): a grid
    over its type still plans, and each variant runs in its engine."""
    engines = "pybullet,mujoco,drake"
    r = CliRunner().invoke(
        main,
        ["sweep", "catch_optimised", "--grid", f"plant.params.engine.type={engines}"]
        + ["--set", "timing.duration=0.45", "--no-logs", "-q", "-o", str(tmp_path)],
    )
    assert r.exit_code == 0, r.output
    rows = read_table(tmp_path / "table.csv")
    assert [row["plant.params.engine.type"] for row in rows] == engines.split(",")
    assert all(row["reason"] == "caught" for row in rows), rows  # (each engine catches)
    r = CliRunner().invoke(
        main,
        [
            "sweep",
            "catch_optimised",
            "--grid",
            "plant.params.engine.typo=1",
            "-o",
            str(tmp_path / "x"),
        ],
    )
    assert r.exit_code == 2 and "no field" in r.output


def test_an_engine_setting_is_an_axis_beside_the_engine_axis(project_root, tmp_path):
    """A setting of an engine the grid itself chooses (the shipped scenario's engine is empty):
    checked with the other axes' first values set, as its variants will run, not alone ("no
    field 'engine' in plant.params")."""
    r = CliRunner().invoke(
        main,
        ["sweep", "catch_optimised", "--grid", "plant.params.engine.mj_iterations=10,50"]
        + ["--grid", "plant.params.engine.type=mujoco", "--set", "timing.duration=0.02"]
        + ["--no-logs", "-q", "-o", str(tmp_path)],
    )
    assert r.exit_code == 0, r.output
    rows = read_table(tmp_path / "table.csv")
    assert [row["plant.params.engine.mj_iterations"] for row in rows] == ["10", "50"]
