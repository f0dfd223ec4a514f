"""``replay sweep``, ``replay ablate`` and ``replay report``: registered into replay.cli by
:func:`register`. Bad input gets one line and exit code 2."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from replay.sweep.executors import EXECUTORS, ExecutorError
from replay.sweep.spec import SweepSpecError

SWEEP_DIR = Path("sweeps")
DEFAULT_SWEEP_OUT = Path("out/sweeps")
DEFAULT_ABLATION_OUT = Path("out/ablations")


def _fail(message: str, code: int = 2) -> None:
    click.echo(f"error: {message}", err=True)
    sys.exit(code)


@click.command()
@click.argument("scenario", type=click.Path(dir_okay=False))
@click.option("--grid", "grids", multiple=True, metavar="KEY.PATH=A,B,C",
              help="vary a field over these values (repeatable: the cartesian product); "
                   "scenario=a.yaml,b.yaml varies the scenario file")
@click.option("--random", "randoms", multiple=True, metavar="KEY.PATH=LO:HI",
              help="draw the field uniformly from [LO, HI] (repeatable), --n times")
@click.option("--n", "n", type=int, help="random draws (default 10 with --random)")
@click.option("--set", "sets", multiple=True, metavar="KEY.PATH=VALUE",
              help="fix a field for every variant (repeatable)")
@click.option("--seed", type=int, default=0, show_default=True,
              help="seed of every variant's run and of the random draws")
@click.option("-o", "--out", type=click.Path(file_okay=False),
              help="directory for table.csv and logs/ (default out/sweeps/NAME)")
@click.option("--workers", type=click.IntRange(min=1),
              help="parallel variants (default: this machine's cores)")
@click.option("--executor", type=click.Choice(EXECUTORS), default="local", show_default=True)
@click.option("--address", help="Ray cluster to join (auto or HOST:PORT); default: a private "
                                "local Ray")
@click.option("--no-logs", is_flag=True, help="do not keep each variant's MCAP log")
@click.option("-q", "--quiet", is_flag=True, help="no progress bar")
def sweep(scenario, grids, randoms, n, sets, seed, out, workers, executor, address, no_logs,
          quiet):
    """Run SCENARIO over a grid and/or random draws of its fields: one table row per variant
    (outcome, metrics, wall time, log). Reruns skip the variants already in the table."""
    from replay.scenario import ScenarioError, load_scenario
    from replay.sweep.spec import from_options
    try:
        spec = from_options(grids, randoms, n)
    except SweepSpecError as exc:
        _fail(str(exc))
    if not spec.columns:
        _fail("nothing to vary: give at least one --grid or --random")
    if seed < 0:
        _fail(f"--seed: expected a seed >= 0, got {seed}")
    try:
        base = load_scenario(scenario, sets=list(sets))
    except ScenarioError as exc:
        _fail(str(exc))
    out = Path(out) if out else DEFAULT_SWEEP_OUT / base.name
    summary = _run(scenario, spec, seed, sets, out, workers, executor, address, not no_logs,
                   not quiet)
    click.echo(summary.line())
    if summary.interrupted:
        sys.exit(130)


def _run(scenario, spec, seed, sets, out, workers, executor, address, keep_logs, progress):
    from replay.sweep.engine import run_sweep
    from replay.sweep.variants import check_keys, expand
    if executor != "ray" and address:
        _fail("--address is for --executor ray")
    try:
        check_keys(scenario, spec, list(sets))
    except SweepSpecError as exc:
        _fail(str(exc))
    variants = expand(scenario, spec, seed, sets=list(sets))
    try:
        return run_sweep(variants, out, workers=workers, executor=executor, address=address,
                         keep_logs=keep_logs, progress=progress)
    except ExecutorError as exc:
        _fail(str(exc))


def register(group: click.Group) -> None:
    """Add this package's commands to the ``replay`` group."""
    group.add_command(sweep)
