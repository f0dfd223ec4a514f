"""Golden-log regression: a fresh run matches the stored log; a changed run is caught, named."""

from click.testing import CliRunner

from replay.cli import main
from replay.golden import compare_logs, load_manifest
from replay.runner import Runner
from replay.scenario import load_scenario


def test_stick_golden_check_passes(project_root):
    r = CliRunner().invoke(main, ["golden", "check", "stick_3step"])
    assert r.exit_code == 0, r.output
    assert "ok   stick_3step" in r.output


def test_a_changed_run_names_its_first_difference(project_root, tmp_path):
    g = load_manifest()["stick_3step"]
    sc = load_scenario(g.scenario, sets=g.sets + ["plant.params.stick.restitution=0.2"])
    run = Runner(sc).run(tmp_path / "changed.mcap").path
    diffs = compare_logs(g.log, run, g.tolerances, g.default_tolerance)
    assert diffs
    first = diffs[0]
    # the resolved scenario text differs first (t = 0); physics differs at the first collision
    assert first.topic == "/scenario" and first.field == "yaml"
    physics = [d for d in diffs if d.topic == "/stick/state"]
    assert physics and abs(physics[0].t - 0.31) < 0.01
    assert "/stick/state message #" in str(physics[0]) and "golden" in str(physics[0])


def test_unknown_golden_is_one_line(project_root):
    r = CliRunner().invoke(main, ["golden", "check", "nope"])
    assert r.exit_code == 2 and "unknown golden log 'nope'" in r.output


def test_a_run_that_crashes_fails_its_golden_and_the_rest_are_checked(project_root, monkeypatch):
    import replay.golden as golden

    real = golden.run_golden

    def crash_one(g, out, progress=None):
        if g.name == "catch_optimised":
            raise AttributeError("'Plant' object has no attribute 'Engine'")
        return real(g, out, progress)

    monkeypatch.setattr(golden, "run_golden", crash_one)
    r = CliRunner().invoke(main, ["golden", "check", "-q", "catch_optimised", "stick_3step"])
    assert r.exit_code == 1 and "Traceback" not in r.output, r.output
    assert "FAIL catch_optimised: the run failed: AttributeError: 'Plant' object" in r.output
    assert "ok   stick_3step" in r.output
