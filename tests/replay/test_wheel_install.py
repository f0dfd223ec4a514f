"""The package as a user installs it: a non-editable wheel in a fresh venv, used from an empty
directory (no checkout on the path), finds its scenarios, robot tables, claims and inputs."""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _sh(args, cwd, timeout=900, env=None):
    r = subprocess.run(
        [str(a) for a in args], cwd=cwd, capture_output=True, text=True, timeout=timeout, env=env
    )
    assert r.returncode == 0, f"{args}: rc {r.returncode}\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    return r.stdout + r.stderr


def _sources(base: Path) -> Path:
    """A copy of the checkout (its .git too: the wheel records the commit): no build/ of an
    earlier build (setuptools would reuse its stale files, e.g. a removed sweep), no in-place
    .so files, no venv."""
    skip = shutil.ignore_patterns(
        ".venv", "build", "out", "*.egg-info", "*.so", "*.pyd", "__pycache__"
    )
    shutil.copytree(ROOT, base / "src", ignore=skip)
    return base / "src"


def _venv_with_this_interpreters_packages(venv: Path) -> Path:
    """A venv without pip whose site-packages also sees this interpreter's (the dependencies:
    installing them again from the index took ~70 s of the suite), returning its site-packages;
    that folder's own .pth files are not read, so the checkout's editable install stays out."""
    _sh([sys.executable, "-m", "venv", "--without-pip", venv], cwd=venv.parent)
    site = next((venv / "lib").glob("python3*/site-packages"))
    here = next(p for p in sys.path if p.endswith("site-packages"))
    (site / "deps.pth").write_text(here + "\n")
    return site


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """The wheel (with its accelerator) installed in a fresh venv: (its ``replay`` command, an
    empty folder, the environment)."""
    base = tmp_path_factory.mktemp("wheel")
    dist, venv, work = base / "dist", base / "venv", base / "empty"
    work.mkdir()
    _sh(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation"]
        + ["-w", dist, _sources(base)],
        cwd=base,
    )
    wheel = next(dist.glob("paper_replay-*.whl"))
    # (no PYTHONPATH: a checkout on it, with the egg-info the wheel build leaves there, would
    # make pip take the package as installed already)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    site = _venv_with_this_interpreters_packages(venv)
    _sh([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", site, wheel], base)
    # the console script pip writes from the wheel's entry point, for this venv's python
    script = venv / "bin" / "replay"
    script.write_text(f"#!{venv / 'bin' / 'python'}\nfrom replay.entry import main\nmain()\n")
    script.chmod(0o755)
    probe = "import replay, analysis, plants; print(replay.__file__, analysis.__file__)"
    assert all(
        str(site) in p for p in _sh([venv / "bin" / "python", "-c", probe], work, env=env).split()
    )
    return script, work, env


def test_the_wheel_ships_its_data(installed):
    replay, work, env = installed
    out = _sh([replay, "list"], cwd=work, env=env)
    for name in ("stick_3step", "catch_optimised"):
        assert name in out
    assert "invalid" not in out


def test_one_run_of_each_paper_from_an_empty_directory(installed):
    replay, work, env = installed
    for name in ("stick_3step", "catch_optimised", "grasp_hexahedron"):
        out = _sh(
            [
                replay,
                "run",
                name,
                "--quiet",
                "--set",
                "timing.duration=0.3",
                "-o",
                work / f"{name}.mcap",
            ],
            cwd=work,
            env=env,
        )
        assert (work / f"{name}.mcap").is_file(), out
        assert "Traceback" not in out and "pybullet build time" not in out, out
        info = _sh([replay, "info", work / f"{name}.mcap"], cwd=work, env=env)
        assert "outcome" in info
        _assert_names_a_commit(info)
    out = _sh([replay, "claims", *sorted(work.glob("*.mcap"))], cwd=work, env=env)
    assert "Traceback" not in out
    for title in ("Stick-shaped", "Direct Mapping", "High Speed Grasping"):  # all three tables
        assert title in out, out[-2000:]
    report = work / "report"
    out = _sh([replay, "report", "-o", report, "--logs", work], cwd=work, env=env)
    html = (report / "index.html").read_text(encoding="utf-8")
    images = re.findall(r'<img src="([^"]+)"', html)
    assert images, "the report shows no figure"
    missing = [src for src in images if not (report / src).is_file()]
    assert not missing, missing
    _sh([replay, "figures", *sorted(work.glob("*.mcap")), "-o", work / "figs"], cwd=work, env=env)
    assert any((work / "figs").glob("*.png"))
    out = _sh([replay, "golden", "check", "stick_3step"], cwd=work, env=env)
    assert "ok" in out


def _assert_names_a_commit(info: str) -> None:
    """The log's code version names the checkout's commit the wheel was built from (HEAD, or
    an ancestor of it when a commit landed since the build), not ``+unknown``."""
    found = re.search(r"code 0\.1\.0\+([0-9a-f]{12})\b", info)
    assert found, info[:400]
    r = subprocess.run(
        ["git", "merge-base", "--is-ancestor", found.group(1), "HEAD"], cwd=ROOT, timeout=30
    )
    assert r.returncode == 0, f"{found.group(1)} is not a commit of this checkout"


def test_a_user_scenario_builds_on_a_shipped_one(installed):
    """``replay show`` copies one out; ``extends: NAME`` resolves a shipped scenario by name."""
    replay, work, env = installed
    _sh([replay, "show", "stick_3step", "-o", work / "copy.yaml"], cwd=work, env=env)
    (work / "mine.yaml").write_text("extends: stick_3step\nseed: 5\ntiming:\n  duration: 0.2\n")
    for f in ("copy.yaml", "mine.yaml"):
        out = _sh([replay, "run", f, "--quiet", "-o", work / f"{f}.mcap"], cwd=work, env=env)
        assert (work / f"{f}.mcap").is_file(), out
    assert "seed 5" in _sh([replay, "info", work / "mine.yaml.mcap"], cwd=work, env=env)


def test_a_controller_from_a_file_runs_and_its_log_is_analysed_elsewhere(installed, tmp_path):
    """Issue #37's plug-in "done when": examples/my_controller.py beside its scenario in a user's
    folder (no packaging) runs; ``figures``, ``claims``, ``report`` and ``compare`` succeed on
    its log beside the paper's run and say what they skipped, in that folder and in one where
    the file is absent."""

    replay, _, env = installed
    mine, other = tmp_path / "mine", tmp_path / "other"
    mine.mkdir()
    other.mkdir()
    for f in ("my_controller.py", "my_controller.yaml"):
        shutil.copy(ROOT / "examples" / f, mine)
    _sh([replay, "run", "my_controller.yaml", "--quiet", "-o", "keeper.mcap"], cwd=mine, env=env)
    _sh([replay, "run", "catch_optimised", "--quiet", "-o", "opt.mcap"], cwd=mine, env=env)
    for f in ("keeper.mcap", "opt.mcap"):
        shutil.copy(mine / f, other)
    skipped = "catch Fig. 7 left out: the log has no /effector/state, /arm/joint_command"
    for folder in (mine, other):
        logs = ["keeper.mcap", "opt.mcap"]
        said = {
            "figures": _sh([replay, "figures", *logs, "-o", "figs"], cwd=folder, env=env),
            "claims alone": _sh([replay, "claims", "keeper.mcap"], cwd=folder, env=env),
            "claims": _sh([replay, "claims", *logs], cwd=folder, env=env),
            "compare": _sh([replay, "compare", *logs, "-o", "cmp"], cwd=folder, env=env),
            "info": _sh([replay, "info", "keeper.mcap"], cwd=folder, env=env),
        }
        _sh([replay, "report", "-o", "report", "--logs", "."], cwd=folder, env=env)
        said["report"] = (folder / "report" / "index.md").read_text(encoding="utf-8")
        for what, out in said.items():
            assert "Traceback" not in out and "unknown controller" not in out, (what, out[-2000:])
        for what in ("figures", "compare", "report"):  # the paper's overlay, Figs. 6-9
            assert "catch_goalkeeper: in no figure (catch Fig. 6 left out" in said[what], what
            assert skipped in said[what], (what, said[what][-2000:])
        assert "claims (arm capability rows) left out: the log has no" in said["claims alone"]
        assert "catch_goalkeeper: 90° in" in said["claims"]  # (a row that reads what it has)
        assert "controller my_controller:GoalKeeper" in said["compare"]
        assert "catch_goalkeeper is not shipped, its nearest is catch_optimised" in said["report"]
        assert (folder / "figs" / "catch_fig7.png").is_file()


def test_a_wheel_built_without_a_c_compiler_has_no_compiled_code_and_runs(tmp_path):
    """``CC=/bin/false``: every accelerator fails to build and is left out (setup.py), the
    wheel still builds, holds no compiled module, and one short run of each paper, ``replay
    claims`` and ``replay report`` work on the pure-Python paths."""
    import zipfile

    dist, venv, work = tmp_path / "dist", tmp_path / "venv", tmp_path / "empty"
    work.mkdir()
    src = _sources(tmp_path)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    out = _sh(
        [sys.executable, "-m", "pip", "wheel", "-v", "--no-deps", "--no-build-isolation"]
        + ["-w", dist, src],
        cwd=tmp_path,
        env={**env, "CC": "/bin/false", "CXX": "/bin/false"},
    )
    assert "not built" in out  # the accelerators said they were left out
    wheel = next(dist.glob("paper_replay-*.whl"))
    compiled = [n for n in zipfile.ZipFile(wheel).namelist() if n.endswith((".so", ".pyd"))]
    assert compiled == []
    site = _venv_with_this_interpreters_packages(venv)  # only the package is new
    _sh([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", site, wheel], work)

    def replay(*args) -> str:
        code = (
            f"import sys; from replay.entry import main; sys.argv = {['replay', *args]!r}; main()"
        )
        return _sh([venv / "bin" / "python", "-c", code], cwd=work, env=env)

    for name in ("stick_3step", "catch_optimised", "grasp_hexahedron"):
        log = work / f"{name}.mcap"
        out = replay("run", name, "--quiet", "--set", "timing.duration=0.3", "-o", str(log))
        assert log.is_file() and "Traceback" not in out, out
    out = replay("claims", *sorted(str(p) for p in work.glob("*.mcap")))
    for title in ("Stick-shaped", "Direct Mapping", "High Speed Grasping"):  # all three tables
        assert title in out, out[-2000:]
    replay("report", "-o", str(work / "report"), "--logs", str(work))
    assert "<img src=" in (work / "report" / "index.html").read_text(encoding="utf-8")
    probe = "import replay.sensors.raster as r, replay.accel as a; print(r._pixels, a.__file__)"
    out = _sh([venv / "bin" / "python", "-c", probe], cwd=work, env=env)
    assert out.startswith("None ") and str(site) in out


def test_the_python_api_from_the_wheel(installed):
    """replay.run / replay.open_log from an empty folder: a kept run's table is what its log
    holds, and a run in memory gives the same numbers and writes no file."""
    replay, work, env = installed
    api = work / "api"
    api.mkdir()
    code = (
        "import replay\n"
        "from replay.log import LogReader\n"
        "kept = replay.run({'extends': 'stick_3step'}, set={'timing.duration': 0.35}, "
        "log='api.mcap')\n"
        "logged = [m.data['omega'] for m in LogReader('api.mcap').messages('/stick/state')]\n"
        "assert kept.table('/stick/state')['omega'].tolist() == logged\n"
        "assert replay.open_log('api.mcap').table('/stick/state')['omega'].tolist() == logged\n"
        "mem = replay.run('stick_3step', set=['timing.duration=0.35'])\n"
        "assert mem.path is None and mem.table('/stick/state')['omega'].tolist() == logged\n"
        "print('api ok', len(logged))\n"
    )
    out = _sh([replay.parent / "python", "-c", code], cwd=api, env=env)
    assert "api ok 35" in out, out[-2000:]  # 0.35 s of /stick/state at 1 kHz: 350 or 351
    assert sorted(p.name for p in api.iterdir()) == ["api.mcap"]


def test_variants_of_an_experiment_are_overlaid_and_labelled_from_an_empty_folder(
    installed, tmp_path
):
    """Issue #37's first "done when": the paper's catch pair plus a variant that differs in one
    parameter, and two stick runs at two frictions, from a non-editable install in an empty
    folder: the report's figures name every run by its difference, none is left out, and
    `compare` puts the variant beside the paper's run."""
    replay, _, env = installed
    work = tmp_path / "runs"
    for decoy in ("analysis", "plants"):  # a user's folders of the installed packages' names
        (work / decoy).mkdir(parents=True)
        (work / decoy / "__init__.py").write_text("MINE = True\n")
    runs = {
        "catch_optimised": ["catch_optimised"],
        "catch_initial": ["catch_initial"],
        "lat10": ["catch_optimised", "--set", "sensors.stereo.latency=0.01"],
        "stick_mu03": ["stick_3step", "--set", "plant.params.stick.friction=0.3"],
        "stick_mu10": ["stick_3step", "--set", "plant.params.stick.friction=1.0"],
    }
    for name, args in runs.items():
        _sh([replay, "run", *args, "--quiet", "-o", work / f"{name}.mcap"], cwd=work, env=env)
    out = _sh([replay, "figures", *sorted(work.glob("*.mcap")), "-o", "figs"], cwd=work, env=env)
    assert "in no figure" not in out and "Traceback" not in out, out[-2000:]
    _sh([replay, "report", "-o", "report", "--logs", work], cwd=work, env=env)
    html = (work / "report" / "index.html").read_text(encoding="utf-8")
    captions = re.findall(r"<figcaption>(.*?)</figcaption>", html, re.S)
    for fig in ("Fig. 6", "Fig. 7", "Fig. 8", "Fig. 9"):
        caption = next(c for c in captions if c.startswith(fig) and "catch_initial" in c)
        assert "catch_optimised (stereo latency 10 ms)" in caption, caption
    stick = [c for c in captions if "stick_3step" in c and "friction" in c]
    assert stick, [c[:120] for c in captions]
    out = _sh(
        [replay, "compare", work / "catch_optimised.mcap", work / "lat10.mcap", "--no-figures"],
        cwd=work,
        env=env,
    )
    assert "latency" in out and "Traceback" not in out, out[-2000:]


def test_the_environments_from_the_wheel(installed):
    """Gymnasium's check_env for the three tasks; the paper's method through each environment
    gives replay run's outcome and log (zero tolerance) on two seeds; `replay evaluate` prints
    the example policy's and the paper's rates with intervals for each task, on two held-out
    inputs."""
    replay, work, env = installed
    here = work / "envs"
    here.mkdir()
    code = (
        "import warnings, gymnasium, replay.envs\n"
        "from gymnasium.utils.env_checker import check_env\n"
        "from replay.envs.policies import PaperPolicy\n"
        "from replay.golden import compare_logs\n"
        "from replay.runner import Runner\n"
        "from replay.scenario import load_scenario\n"
        "short = {'stick': 0.4, 'catch': 0.4, 'grasp': 0.1}\n"
        "for task, (env_id, name) in sorted(replay.envs.TASKS.items()):\n"
        "    with warnings.catch_warnings():\n"
        "        warnings.simplefilter('ignore')\n"
        "        check_env(gymnasium.make(env_id, set={'timing.duration': 0.02}).unwrapped)\n"
        "    for seed in (2, 5):\n"
        "        d = short[task]\n"
        "        e = gymnasium.make(env_id, set={'timing.duration': d}, log=f'{task}{seed}.mcap')\n"
        "        policy = PaperPolicy(e)\n"
        "        obs, info = e.reset(seed=seed, options=policy.reset_options)\n"
        "        done = False\n"
        "        while not done:\n"
        "            obs, r, term, trunc, info = e.step(policy(obs, info))\n"
        "            done = term or trunc\n"
        "        sc = load_scenario(name, [f'timing.duration={d}'], seed)\n"
        "        run = Runner(sc).run(f'run_{task}{seed}.mcap')\n"
        "        assert info['outcome'] == run.outcome, (task, seed)\n"
        "        exact = {'abs': 0, 'rel': 0}\n"
        "        assert compare_logs(run.path, info['result'].path, {}, exact) == [], (task, seed)\n"
        "    print('env ok', task)\n"
    )
    out = _sh([replay.parent / "python", "-c", code], cwd=here, env=env)
    assert [line for line in out.splitlines() if line.startswith("env ok")] == [
        "env ok catch",
        "env ok grasp",
        "env ok stick",
    ], out[-2000:]
    shutil.copy(ROOT / "examples" / "my_policy.py", here)
    for task, sets in (
        ("catch", []),
        ("stick", ["--set", "timing.duration=0.5"]),
        ("grasp", ["--set", "timing.duration=0.2"]),
    ):
        out = _sh(
            [replay, "evaluate", f"my_policy:{task}", "--task", task, "--n", "2", *sets],
            cwd=here,
            env=env,
        )
        rows = re.findall(r"^(\S.*?)\s+\d+/2\s+[\d.]+ %\s+\[\s*[\d.]+,\s*[\d.]+\] %$", out, re.M)
        assert rows == [f"my_policy:{task}", "paper (the paper's method)"], out
        # the held-out inputs come from the wheel's analysis through its entry point
        assert "input set held-out, episodes 0..1: 2 distinct physical inputs" in out, out
