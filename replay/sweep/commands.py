"""``replay sweep`` and ``replay ablate``: registered into replay.cli by
:func:`register`. Bad input gets one line and exit code 2."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from replay import completion as complete
from replay import registry
from replay.console import exit_code, fail, note, warn
from replay.log import LogError
from replay.scenario.schema import LOG_LEVELS
from replay.sweep.executors import EXECUTORS, ExecutorError
from replay.sweep.lock import SweepOutputError
from replay.sweep.spec import SweepSpecError
from replay.sweep.table import TableError

DEFAULT_SWEEP_OUT = Path("out/sweeps")


@click.command()
@click.argument("scenario", type=click.Path(dir_okay=False), shell_complete=complete.scenario)
@click.option(
    "--grid",
    "grids",
    multiple=True,
    metavar="KEY.PATH=A,B,C",
    help="vary a field over these values (repeatable: the cartesian product); "
    "scenario=a.yaml,b.yaml varies the scenario file",
)
@click.option(
    "--random",
    "randoms",
    multiple=True,
    metavar="KEY.PATH=LO:HI",
    help="draw the field uniformly from [LO, HI] (repeatable), --n times",
)
@click.option("--n", "n", type=int, help="random draws (default 10 with --random)")
@click.option(
    "--set",
    "sets",
    multiple=True,
    metavar="KEY.PATH=VALUE",
    help="fix a field for every variant (repeatable)",
)
@click.option(
    "--seed",
    type=int,
    default=0,
    show_default=True,
    help="seed of every variant's run and of the random draws",
)
@click.option(
    "-o",
    "--out",
    type=click.Path(file_okay=False),
    help="directory for table.csv and logs/ (default out/sweeps/NAME)",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    help="parallel variants (default: this machine's cores)",
)
@click.option("--executor", type=click.Choice(EXECUTORS), default="local", show_default=True)
@click.option(
    "--address",
    help="Ray cluster to join (auto or HOST:PORT); default: a private Ray on 127.0.0.1, "
    "ended with the sweep",
)
@click.option(
    "--no-logs",
    is_flag=True,
    help="keep no variant's MCAP log: none is written (a metrics function reads the run's "
    "messages in memory); the rows are the same",
)
@click.option(
    "--log-level",
    type=click.Choice(LOG_LEVELS),
    help="what each variant's log holds (as --set log.level=LEVEL; default: the scenario's log:)",
)
@click.option(
    "--retry-failed",
    is_flag=True,
    help="re-run the variants whose row says they failed to run (error:/invalid:)",
)
@click.option("-q", "--quiet", is_flag=True, help="no progress bar")
def sweep(
    scenario,
    grids,
    randoms,
    n,
    sets,
    seed,
    out,
    workers,
    executor,
    address,
    no_logs,
    log_level,
    retry_failed,
    quiet,
):
    """Run SCENARIO (a file, or a shipped scenario's name) over a grid and/or random draws of its fields: one table row per variant
    (outcome, metrics, wall time, log). Reruns skip the variants already in the table."""
    from replay.resources import find_scenario
    from replay.scenario import ScenarioError, load_scenario
    from replay.sweep.spec import check_seed, from_options

    scenario = find_scenario(scenario)
    sets = (*sets, f"log.level={log_level}") if log_level else sets
    try:
        spec = from_options(grids, randoms, n)
    except SweepSpecError as exc:
        fail(str(exc))
    if not spec.columns:
        fail("nothing to vary: give at least one --grid or --random")
    try:
        check_seed(seed, "--seed")  # (before anything is planned: every variant's seed)
    except SweepSpecError as exc:
        fail(str(exc))
    try:
        base = load_scenario(scenario, sets=list(sets))
    except ScenarioError as exc:
        fail(str(exc))
    out = Path(out) if out else DEFAULT_SWEEP_OUT / base.name
    summary = _run(
        scenario,
        spec,
        seed,
        sets,
        out,
        workers,
        executor,
        address,
        not no_logs,
        not quiet,
        retry_failed=retry_failed,
    )
    if summary.rows:
        _plot(out)
    click.echo(summary.line())
    if summary.interrupted:
        sys.exit(143 if summary.terminated else 130)


def _plot(out: Path) -> None:
    """Each installed sweep plot (the ``paper_replay.sweep_plots`` entry points; analysis's
    draws ``out/summary.png``/``.svg``, each cell's rate) from ``out/summary.csv``; a plot that
    cannot be written is a warning, the sweep's table and summary being written already."""
    for name in registry.names("sweep_plot"):
        try:
            registry.load("sweep_plot", name)(out / "summary.csv", out)
        except (LogError, OSError, TableError) as exc:
            warn(f"no plot of the sweep: {exc}")


def _run(
    scenario,
    spec,
    seed,
    sets,
    out,
    workers,
    executor,
    address,
    keep_logs,
    progress,
    metrics="",
    retry_failed=False,
):
    from replay.sweep.engine import make_folder, planned, run_sweep
    from replay.sweep.variants import check_keys, code_version, plan

    if executor != "ray" and address:
        fail("--address is for --executor ray")
    try:
        spec.check_count()  # (before anything is made)
        check_keys(scenario, spec, list(sets))
        make_folder(out)
    except SweepSpecError as exc:
        fail(str(exc))
    except SweepOutputError as exc:
        fail(str(exc), code=exc.code)
    if progress:  # (-q: the summary line only)
        note(f"sweep: {spec.count:,} variant{'s' if spec.count != 1 else ''} to plan")
    try:
        # the metrics function makes columns: a different one is a different row
        version = code_version() + (f"|{metrics}" if metrics else "")
        variants = planned(
            plan(scenario, spec, seed, sets=list(sets), version=version), spec.count, progress
        )
    except SweepSpecError as exc:
        fail(str(exc))
    try:
        return run_sweep(
            variants,
            out,
            workers=workers,
            executor=executor,
            address=address,
            keep_logs=keep_logs,
            progress=progress,
            metrics=metrics,
            retry_failed=retry_failed,
        )
    except ExecutorError as exc:
        fail(str(exc))
    except (SweepOutputError, TableError) as exc:
        fail(str(exc), code=exc.code)


@click.command()
@click.argument("names", nargs=-1, shell_complete=complete.ablation)
@click.option("--list", "list_", is_flag=True, help="list the ablations (sweeps/*.yaml)")
@click.option("--workers", type=click.IntRange(min=1), help="parallel variants")
@click.option("--executor", type=click.Choice(EXECUTORS), default="local", show_default=True)
@click.option("--address", help="Ray cluster to join (with --executor ray)")
@click.option(
    "--store",
    is_flag=True,
    help="also keep each table as data/ablations/NAME.csv "
    "(what the report plots without a fresh run)",
)
@click.option("--plot-only", is_flag=True, help="no runs: redraw from the freshest table")
@click.option(
    "--no-logs",
    is_flag=True,
    help="keep no variant's MCAP log: none is written (a temporary one only where the sweep's "
    "metrics function reads it); the rows are the same",
)
@click.option("--retry-failed", is_flag=True, help="re-run variants that failed to run")
@click.option("-q", "--quiet", is_flag=True, help="no progress bar")
def ablate(
    names, list_, workers, executor, address, store, plot_only, no_logs, retry_failed, quiet
):
    """Run the named ablations (sweeps/NAME.yaml; all with no NAME) and draw each plot from its
    table into out/ablations/NAME/."""
    from replay.sweep import ablations

    if list_:
        for name in ablations.names():
            sf = ablations.load(name)
            click.echo(f"{name:<28} {sf.paper:<16} {sf.description}")
        return
    try:
        files = [ablations.load(n) for n in (names or ablations.names())]
    except SweepSpecError as exc:
        fail(str(exc))
    for sf in files:
        out = ablations.OUT_DIR / sf.name
        if plot_only:
            table, _ = ablations.table_path(sf.name)
            if table is None:
                fail(f"{sf.name}: no table yet (run `replay ablate {sf.name}`)")
        else:
            summary = _run(
                str(sf.scenario),
                sf.spec,
                sf.seed,
                sf.sets,
                out,
                workers,
                executor,
                address,
                not no_logs,
                not quiet,
                metrics=sf.metrics,
                retry_failed=retry_failed,
            )
            click.echo(f"{sf.name}: {summary.line(outcomes=not sf.summary)}")
            if summary.interrupted:
                sys.exit(143 if summary.terminated else 130)
            if sf.summary and summary.rows:  # the ablation's own measure
                from replay.sweep.worker import load_function

                click.echo(f"{sf.name}: {load_function(sf.summary)(summary.rows)}")
            table = summary.table
            if store:
                try:
                    click.echo(f"stored: {ablations.store(sf.name, table)}")
                except OSError as exc:
                    fail(
                        f"cannot store {sf.name}'s table: {exc.strerror or exc}",
                        code=exit_code(exc),
                    )
        try:
            plots = ablations.plot(sf, table, out)
        except LogError as exc:  # a link or another program's file at a plot's path
            fail(f"{sf.name}: {exc}")
        except OSError as exc:
            fail(
                f"cannot write {sf.name}'s plots to {out}: {exc.strerror or exc}",
                code=exit_code(exc),
            )
        for path in plots:
            click.echo(f"plot: {path}")


def register(group: click.Group) -> None:
    """Add this package's commands to the ``replay`` group."""
    group.add_command(sweep)
    group.add_command(ablate)
