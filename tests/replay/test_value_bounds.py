"""A value that passes the checks before a run is one the run can use (issue #36): a float too
small to be a normal float (1e-320: a simulator dividing by it gets infinity mid-run, 1e-400:
read as 0) is refused by the loader, and a sweep's seed out of a scenario's range (0 to
2^63 - 1) is refused before any variant is planned or any folder made."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from replay.cli import main
from replay.scenario import ScenarioError, load_scenario
from replay.sweep.spec import SweepSpecError, check_seed, load_sweep_file


def _errors(r) -> list[str]:
    return [x for x in r.stderr.splitlines() if x.strip()]


@pytest.mark.parametrize("value", ["1e-320", "-4.9e-324", "1e-400", "2.2e-308", "1_0e-400"])
@pytest.mark.parametrize("key", ["controller.params.target", "plant.params.x0"])
def test_a_float_too_small_to_represent_is_refused(toy_yaml, key, value):
    with pytest.raises(ScenarioError) as err:
        load_scenario(toy_yaml, sets=[f"{key}={value}"])
    text = str(err.value)
    assert key in text and "too small, not representable" in text and "\n" not in text


@pytest.mark.parametrize(
    "value", ["0", "0.0", "-0.0", "0e-400", "2.2250738585072014e-308", "1e-300"]
)
def test_zero_and_normal_floats_still_load(toy_yaml, value):
    sc = load_scenario(toy_yaml, sets=[f"controller.params.target={value}"])
    assert sc.controller.params.target == float(value)


def test_validate_refuses_what_run_would_fail_on(project_root, tmp_path):
    out = tmp_path / "vr.mcap"
    for args in (
        ["validate", "--static", "--set", "plant.params.stick.mass=1e-320", "stick_3step"],
        ["run", "-q", "--set", "plant.params.stick.mass=1e-320", "stick_3step", "-o", str(out)],
    ):
        r = CliRunner().invoke(main, args, prog_name="replay")
        errors = _errors(r)
        assert r.exit_code == 2 and len(errors) == 1, r.output
        assert errors[0].startswith("error: ") and "too small, not representable" in errors[0]
    assert list(tmp_path.iterdir()) == []  # (before: a .failed.mcap)


# -- a sweep's seed ---------------------------------------------------------------------------


def test_check_seed_takes_a_scenarios_seeds_only():
    assert check_seed(0, "s") == 0 and check_seed(2**63 - 1, "s") == 2**63 - 1
    for bad in (-1, 2**63, 10**23, True, 1.0, "3", None):
        with pytest.raises(SweepSpecError, match="expected a seed from 0 to 2"):
            check_seed(bad, "s")


@pytest.mark.parametrize(
    "args, where",
    [
        (["--seed", str(10**23), "--random", "controller.params.target=0:1"], "--seed"),
        (["--seed", "-1", "--random", "controller.params.target=0:1"], "--seed"),
        (["--grid", f"seed=1,{10**23}"], "--grid seed"),
        (["--random", "seed=-5:5"], "--random seed"),
        (["--random", "seed=0:1.5"], "--random seed"),  # (draws that are not whole)
    ],
)
def test_a_sweep_seed_out_of_range_is_refused_up_front(toy_yaml, tmp_path, args, where):
    out = tmp_path / "sweep"
    r = CliRunner().invoke(
        main, ["sweep", str(toy_yaml), *args, "-o", str(out), "-q"], prog_name="replay"
    )
    errors = _errors(r)
    assert r.exit_code == 2 and len(errors) == 1, r.output
    assert errors[0].startswith(f"error: {where}: expected a seed from 0 to 2^63 - 1")
    assert not out.exists()


def test_a_sweep_files_seed_out_of_range_is_refused(tmp_path):
    path = tmp_path / "s.yaml"
    for seed in (10**23, -1, "'7'"):
        path.write_text(
            f"scenario: x.yaml\nseed: {seed}\ngrid: {{controller.params.target: [1, 2]}}\n"
            "plot: line\n"
        )
        with pytest.raises(SweepSpecError, match="seed: expected a seed from 0 to 2"):
            load_sweep_file(path)


def test_the_bound_is_the_scenarios(toy_yaml):
    assert load_scenario(toy_yaml, seed=2**63 - 1).seed == 2**63 - 1
    with pytest.raises(ScenarioError):
        load_scenario(toy_yaml, seed=2**63)
