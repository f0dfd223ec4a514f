"""The ``replay`` command line. Bad input gets one clear line and exit code 2, never a traceback."""

from __future__ import annotations

import errno
import ipaddress
import sys
from pathlib import Path

import click
import numpy as np

from replay import completion as complete
from replay import registry
from replay.console import (
    RunProgress,
    bar,
    bars_on,
    fail,
    note,
    printable_streams,
    read_log,
    say,
    warn,
    write_text,
)
from replay.interfaces import Plant
from replay.log import LogError, LogReader
from replay.log.errors import LogWriteError
from replay.log.output import (
    OutputConflictError,
    check_output,
    live_writers,
    own_part,
    part_pid,
)
from replay.resources import DEFAULT_LOG_DIR, find_scenario, scenario_dir
from replay.scenario import ScenarioError, load_scenario
from replay.scenario.schema import LOG_LEVELS
from replay.scenario.yamlio import one_line
from replay.viewer.timeline import DEFAULT_SPEED, SPEEDS


_NoArgsIsHelp = getattr(click.exceptions, "NoArgsIsHelpError", ())  # click >= 8.2


class _Group(click.Group):
    """Ctrl-C outside a run (loading, reading logs, figures) exits 130 quietly, not "Aborted!";
    a usage error (a missing argument, an unknown option, a bad option value) is one line with
    the same ``error:`` prefix as every other user error, exit code 2."""

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            click.echo("interrupted", err=True)
            sys.exit(130)

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode, **extra)
        printable_streams()  # (ω, … on a latin-1 or ASCII terminal: fallbacks, no traceback)
        try:
            code = super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        except _NoArgsIsHelp as exc:  # `replay` or `replay golden` alone: the help
            exc.show()
            sys.exit(exc.exit_code)
        except click.UsageError as exc:
            where = exc.ctx.command_path if exc.ctx else "replay"
            fail(f"{exc.format_message()} (see `{where} --help`)", code=exc.exit_code)
        except click.ClickException as exc:
            fail(exc.format_message(), code=exc.exit_code)
        except click.Abort:
            click.echo("interrupted", err=True)
            sys.exit(130)
        sys.exit(code if isinstance(code, int) else 0)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="paper-replay")
def main() -> None:
    """paper-replay: re-run landmark high-speed robotics experiments from YAML scenarios."""


def _load(path: str, sets=(), seed=None):
    try:
        return load_scenario(find_scenario(path), sets=list(sets), seed=seed)
    except ScenarioError as exc:
        fail(str(exc))


@main.command()
@click.argument("scenario", type=click.Path(dir_okay=False), shell_complete=complete.scenario)
@click.option("-o", "--out", type=click.Path(), help="log path (default out/logs/NAME.mcap)")
@click.option(
    "--set",
    "sets",
    multiple=True,
    metavar="KEY.PATH=VALUE",
    help="override a scenario field (repeatable)",
)
@click.option("--seed", type=int, help="override the scenario's seed")
@click.option(
    "--log-level",
    type=click.Choice(LOG_LEVELS),
    help="what the log holds (as --set log.level=LEVEL; default: the scenario's log:, else full)",
)
@click.option("-q", "--quiet", is_flag=True, help="no progress bar and no summary, only errors")
@click.option(
    "--view",
    is_flag=True,
    help="show the run live in the browser viewer "
    "(http://127.0.0.1:8080, or the next free port), then stay for replay (Ctrl-C)",
)
def run(scenario, out, sets, seed, log_level, quiet, view):
    """Run SCENARIO and write its MCAP log."""
    from replay.runner import RunInterrupted, Runner

    sets = (*sets, f"log.level={log_level}") if log_level else sets
    sc = _load(scenario, sets, seed)
    out = Path(out) if out else DEFAULT_LOG_DIR / f"{sc.name}.mcap"
    _check_log_path(out, sc)
    progress = RunProgress(sc.name, bars_on(quiet))
    runner = _runner(scenario, sc, Runner, progress=progress)
    live = _live_viewer() if view else None
    if live:
        runner.observers = (live.observe,)
    try:
        result = runner.run(out)
    except RunInterrupted as exc:
        progress.done()
        if live:
            live.stop()
        click.echo(
            f"interrupted at t = {exc.result.t_end:.4f} s; partial log kept: {exc.result.path}",
            err=True,
        )
        sys.exit(130)
    except LogWriteError as exc:  # a full disk, an I/O error: a system fault, exit 1
        progress.done()
        if live:
            live.stop()
        part = own_part(out)
        if part is not None and exc.errno in (errno.ENOSPC, errno.EDQUOT):
            part.unlink(missing_ok=True)  # what it holds is not worth the disk it fills
            fail(f"{exc}; the run stopped and its partial log is removed", code=1)
        fail(f"{exc}; the run stopped" + (f", partial log: {part}" if part else ""), code=1)
    except OutputConflictError as exc:
        progress.done()
        if live:
            live.stop()
        fail(str(exc), code=1)
    except LogError as exc:
        progress.done()
        if live:
            live.stop()
        fail(str(exc))
    except Exception as exc:  # noqa: BLE001 - a plug-in failed mid-run: one line, the .part kept
        progress.done()
        if live:
            live.stop()
        part = own_part(out)
        fail(f"the run failed: {type(exc).__name__}: {exc}; partial log: {part}", code=1)
    progress.done()
    failed = result.stopped_by == "error"
    if failed and not live:
        fail(f"{result.error} at t = {result.t_end:.4f} s; log kept: {result.path}", code=1)
    if failed:
        click.echo(
            f"error: {one_line(result.error)} at t = {result.t_end:.4f} s; log kept: {result.path}",
            err=True,
        )
    if not quiet and not failed:
        events = ", ".join(f"{k} x{n}" for k, n in sorted(result.events.items())) or "none"
        click.echo(
            f"{sc.name}: {result.t_end:.3f} s simulated in {result.wall_time:.2f} s "
            f"(stopped by {result.stopped_by}); events: {events}"
        )
        click.echo(f"log: {result.path}")
    if live:
        _replay_live(live, result.path)
        if failed:
            sys.exit(1)


def _check_log_path(out: Path, sc) -> None:
    """One line before anything runs: never overwrite an input, a folder or a non-log."""
    try:
        target = out.resolve()
    except (OSError, RuntimeError) as exc:
        fail(f"bad log path {out}: {exc}")
    if target in set(getattr(sc, "inputs", ())):
        fail(f"will not write the log over the scenario file {out} (give another -o)")
    try:
        check_output(out)
    except LogError as exc:
        fail(str(exc))
    busy = live_writers(out)
    if busy:  # (LogWriter refuses it too, under a lock: this says it before the plug-ins load)
        fail(
            f"will not write log {out}: another run (process {part_pid(busy[0], out)}) is "
            f"writing it "
            f"({busy[0].name}); wait for it or give another -o"
        )


_REFUSED = (ValueError, TypeError, KeyError, IndexError, ArithmeticError, OSError, LogError)
_PARTS = (
    ("/plants/", "plant"),
    ("/replay/sensors/", "sensors"),
    ("/replay/control/", "controller"),
)


def _refusal(scenario: str, exc: BaseException) -> str:
    """One line: which plug-in refused the scenario (from where it raised) and why."""
    part = "plug-ins"
    tb = exc.__traceback__
    while tb is not None:
        name = tb.tb_frame.f_code.co_filename.replace("\\", "/")
        found = next((label for key, label in _PARTS if key in name), None)
        if found:
            part = found
            break
        tb = tb.tb_next
    return f"{scenario}: {part}: refused the scenario: {type(exc).__name__}: {exc}"


def _runner(scenario: str, sc, Runner, **kw):
    """The plug-ins built from a validated scenario (what ``validate`` also does); a plug-in
    that still refuses it (a condition only its own model knows) gives one line."""
    try:
        return Runner(sc, **kw)
    except _REFUSED as exc:
        fail(_refusal(scenario, exc))


def _warn_if_exposed(host: str) -> None:
    try:
        local = ipaddress.ip_address(host).is_loopback
    except ValueError:
        local = host == "localhost"
    if not local:
        warn(
            f"serving on {host}: anyone who can reach this machine on the network can see "
            "the viewer (use --host 127.0.0.1 to keep it local)"
        )


def _live_viewer():
    """A browser viewer fed by the runner (``run --view``); its URL printed at once."""
    from replay.viewer import LiveSession, ViewerError

    try:
        live = LiveSession()
    except ViewerError as exc:
        fail(str(exc))
    if live.viewer.port_note:
        note(live.viewer.port_note)
    click.echo(f"viewer: {live.url}  (live while the run computes)", err=True)
    return live


def _replay_live(live, log: Path) -> None:
    from replay.viewer import ViewerError

    if live.error:
        warn(live.error)
    try:
        live.finish(log)
    except ViewerError as exc:
        live.stop()
        fail(str(exc))
    for text in live.viewer.notes:
        warn(text)
    click.echo(f"viewer: {live.url}  (replaying {log}; Ctrl-C to stop)", err=True)
    live.wait()


@main.command()
@click.argument("scenario", type=click.Path(dir_okay=False), shell_complete=complete.scenario)
@click.option(
    "-o",
    "--out",
    type=click.Path(dir_okay=False),
    help="where to write (default: the controller's alpha_file)",
)
@click.option("-q", "--quiet", is_flag=True, help="no progress bar")
def optimise(scenario, out, quiet):
    """Run a controller's offline optimisation from scratch and store its result where the
    scenario reads it (the catching mapping's alpha, eq. 25)."""
    from replay.runner import Runner

    sc = _load(scenario)
    stored = getattr(sc.controller.params, "alpha_file", None)
    if stored is None:
        fail(f"controller {sc.controller.type!r} has no offline optimisation to store")
    if not (out or stored):
        fail("the scenario sets no controller.params.alpha_file: give -o FILE")
    base = getattr(sc.controller.params, "scenario_dir", "")  # files resolve from the scenario
    path = Path(out) if out else Path(base, stored).resolve() if base else Path(stored)
    if not out and base and sc.inputs and Path(base).resolve() != sc.inputs[0].parent.resolve():
        fail(  # (an extended scenario's file, e.g. the shipped mapping: never replaced so)
            f"the alpha_file {path} is named by a scenario {scenario} extends: give -o FILE.json "
            "(and controller.params.alpha_file: FILE.json) for one of its own"
        )
    if path.resolve() in set(sc.inputs) or path.suffix in (".yaml", ".yml", ".mcap"):
        fail(
            f"will not write the optimisation over {path} (a scenario or a log): give -o FILE.json"
        )
    try:
        check_output(path, kind="optimisation result", magic=b"{")
    except LogError as exc:
        fail(str(exc))
    # built without its mapping (mapping: initial) so that the optimisation runs here, from
    # scratch, under a progress bar of its iterations
    fresh = ["controller.params.alpha_file=''"]
    if hasattr(sc.controller.params, "mapping"):
        fresh.append("controller.params.mapping=initial")
    runner = _runner(scenario, _load(scenario, fresh), Runner)
    iterations = int(getattr(sc.controller.params, "max_iterations", 0) or 0) or None
    with bar(iterations, "optimise", unit="it", enabled=bars_on(quiet)) as progress:

        def step(record) -> None:
            if record.iteration:
                progress.update(1)
            progress.set_postfix(cost=f"{record.objective:.4g}", refresh=False)

        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            runner.controller.write_alpha_file(path, progress=step)
        except OSError as exc:
            fail(f"cannot write {path}: {exc.strerror or exc}")
        finally:
            runner.plant.close()
    click.echo(f"wrote {path}")


@main.command()
@click.argument(
    "scenarios", nargs=-1, type=click.Path(dir_okay=False), shell_complete=complete.scenario
)
@click.option("--set", "sets", multiple=True, metavar="KEY.PATH=VALUE")
@click.option(
    "--static",
    is_flag=True,
    help="only the scenario checks: do not build the "
    "plug-ins (faster; a plug-in's own model checks are left to `run`)",
)
def validate(scenarios, sets, static):
    """Check scenario files without running them (all of scenarios/ by default): every field,
    then the plug-ins are built as `run` builds them (the plant, sensors and controller, with
    any offline optimisation), so what passes here runs."""
    from replay.runner import Runner

    paths = scenarios or sorted(str(p) for p in scenario_dir().glob("*.yaml"))
    bad = 0
    for p in paths:
        try:
            sc = load_scenario(find_scenario(p), sets=list(sets))
        except ScenarioError as exc:
            click.echo(f"error: {one_line(str(exc))}", err=True)
            bad += 1
            continue
        if not static:
            try:
                Runner(sc).plant.close()
            except _REFUSED as exc:
                click.echo(f"error: {one_line(_refusal(p, exc))}", err=True)
                bad += 1
                continue
            _warn_unpublished(p, sc)
        click.echo(one_line(f"ok: {p}"))  # (a file name with a line break: still one line)
    if bad:
        sys.exit(2)


def _warn_unpublished(path: str, sc) -> None:
    """A warning from each installed scenario check (the ``paper_replay.checks`` entry points,
    e.g. analysis/published.py: the topics its paper's figures and claims read that ``sc``
    will not publish, from a brief trial run)."""
    for name in registry.names("check"):
        try:
            text = registry.load("check", name)(sc)
        except Exception as exc:  # noqa: BLE001 - a plug-in failing in its first steps: one line
            text = f"its trial run failed, so what it publishes is unknown: {type(exc).__name__}: {exc}"
        if text:
            warn(f"{path}: {text}")


@main.command("list")
@click.option("--plugins", is_flag=True, help="list the installed plug-ins instead")
def list_(plugins):
    """The scenarios (name, paper, description), or the plug-ins."""
    if plugins:
        for kind in registry.GROUPS:
            label = kind if kind.endswith("s") else f"{kind}s"  # figures, claims: already plural
            click.echo(f"{label}: {', '.join(registry.names(kind)) or '-'}")
        return
    for p in sorted(scenario_dir().glob("*.yaml")):
        try:
            sc = load_scenario(p)
        except ScenarioError as exc:
            click.echo(f"{p.stem:<28} (invalid: {exc})")
            continue
        click.echo(one_line(f"{p.stem:<28} {sc.paper:<16} {sc.description}"))


def params_markdown() -> str:
    """Every scenario field and every plug-in's params, with units and ranges (docs/scenarios.md),
    and the settings of each physics engine of the arm rig (entry points paper_replay.engines)."""
    import dataclasses
    from importlib.metadata import entry_points

    from replay.params import describe
    from replay.scenario.schema import (
        ControllerSpec,
        LogSpec,
        PlantSpec,
        Scenario,
        SensorSpec,
        TaskSpec,
    )

    def table(cls, prefix: str) -> list[str]:
        rows = ["| field | unit | default | allowed | meaning |", "|---|---|---|---|---|"]
        nested = []
        for r in describe(cls):
            f = next(f for f in dataclasses.fields(cls) if f.name == r["name"])
            if f.metadata.get("internal"):
                continue
            default = r["default"]
            if dataclasses.is_dataclass(default):
                nested.append((f"{prefix}{r['name']}.", type(default)))
                default = "(see below)"
            rows.append(
                f"| `{prefix}{r['name']}` | {r['unit']} | {default} | {r['range']} | {r['doc']} |"
            )
        out = rows
        for sub_prefix, sub in nested:
            out += ["", f"`{sub_prefix[:-1]}`:", ""] + table(sub, sub_prefix)
        return out

    lines = [
        "# Scenario fields",
        "",
        "Generated by `replay describe` from the code (a test keeps this file in step).",
        "Units are SI. A field without a default is required. A plug-in's `type:` is an",
        "installed plug-in's name (below) or an import path `module:Class`, a module beside the",
        "scenario file or on the Python path (docs/security.md: importing it runs its code).",
        "",
        "## Scenario",
        "",
    ]
    lines += table(Scenario, "")
    for title, cls in (
        ("plant", PlantSpec),
        ("sensors.NAME", SensorSpec),
        ("controller", ControllerSpec),
        ("tasks.NAME", TaskSpec),
        ("log", LogSpec),
    ):
        lines += ["", f"### `{title}`", ""] + table(cls, f"{title}.")
    for kind in ("plant", "sensor", "controller"):
        for name in registry.names(kind):
            cls = registry.load(kind, name)
            if cls.__module__.startswith("toy_plugins"):
                continue
            where = {"plant": "plant", "sensor": "sensors.NAME", "controller": "controller"}[kind]
            doc = (cls.__doc__ or "").strip().splitlines()
            lines += ["", f"## {kind} `{name}`", "", doc[0] if doc else "", ""]
            lines += table(cls.Params, f"{where}.params.")
    for engine in sorted(entry_points(group="paper_replay.engines"), key=lambda e: e.name):
        cls = engine.load()  # (an arm rig's plant.params.engine: its settings, no simulator)
        lines += ["", f"## engine `{engine.name}` (`plant.params.engine`)", ""]
        lines += table(cls, "plant.params.engine.")
    return "\n".join(lines) + "\n"


@main.command()
def describe():
    """Print every scenario field and plug-in parameter (unit, default, range) as Markdown."""
    click.echo(params_markdown(), nl=False)


def _log_notes(name: str, r: LogReader) -> list[str]:
    """One line per thing a reader of this log must know (truncated, damaged, missing)."""
    return [f"{name}: {n}" for n in r.describe_problems()]


@main.command()
@click.argument("log", type=click.Path(dir_okay=False))
@click.option(
    "--events",
    "kinds",
    metavar="KIND[,KIND]",
    help="list only the events of these kinds (e.g. outcome,collision)",
)
@click.option("--no-events", is_flag=True, help="list no events (their count stays)")
def info(log, kinds, no_events):
    """Summarise a LOG: scenario, topics, counts, duration and events."""
    if kinds is not None and no_events:
        fail("--events and --no-events exclude each other")
    wanted = None if kinds is None else {k.strip() for k in kinds.split(",") if k.strip()}
    if wanted is not None and not wanted:
        fail("--events: give one or more event kinds, e.g. --events outcome,collision")
    r = read_log(log)
    try:
        sc = r.scenario()
        click.echo(
            one_line(
                f"scenario: {sc.get('name', '?')} (paper {sc.get('paper', '?')}, "
                f"seed {sc.get('seed', '?')}, code {sc.get('version', '?')})"
            )
        )
    except LogError as exc:  # none, or its stored YAML is not a scenario's (too big, deep, ...)
        missing = str(exc).endswith("no /scenario message")
        click.echo("scenario: (no /scenario message)" if missing else "scenario: (unreadable)")
        if not missing:
            warn(str(exc))
    t0, t1 = r.time_range()
    flag = {"truncated": "  [TRUNCATED log]", "damaged": "  [DAMAGED log]"}.get(r.status, "")
    click.echo(f"duration: {t1 - t0:.4f} s simulated{flag}")
    try:
        events = r.events()
    except LogError as exc:  # (over series_bytes)
        fail(str(exc))
    outcome = next((e["data"] for e in reversed(events) if e["kind"] == "outcome"), None)
    if outcome is None:
        click.echo("outcome: (none: the run did not finish)")
    else:
        metrics = {k: v for k, v in outcome.items() if k not in ("success", "reason")}
        click.echo(
            one_line(
                f"outcome: {'success' if outcome.get('success') else 'FAILED'}: "
                f"{outcome.get('reason', '')}"
            )
        )
        if metrics:
            say("  " + ", ".join(f"{k}={_short(v)}" for k, v in metrics.items()))
    click.echo("topics:")
    for topic, n in r.topic_counts().items():
        click.echo(one_line(f"  {topic:<28} {n:>8}"))
    shown = [] if no_events else [e for e in events if wanted is None or e["kind"] in wanted]
    counted = f" ({len(shown)} shown: {', '.join(sorted(wanted))})" if wanted is not None else ""
    click.echo(one_line(f"events: {len(events)}{counted}"))
    if wanted is not None and not shown and events:
        kinds_seen = sorted({str(e["kind"]) for e in events})
        note(f"no event of kind {', '.join(sorted(wanted))}; this log has {_kinds(kinds_seen)}")
    for e in shown:
        data = e.get("data", {})
        data = data if isinstance(data, dict) else {"data": data}
        brief = ", ".join(f"{k}={_short(v)}" for k, v in list(data.items())[:6])
        t = e.get("t")
        t = f"{t:8.4f}" if isinstance(t, (int, float)) else f"{'?':>8}"
        click.echo(one_line(f"  t = {t} s  {_short(e['kind']):<12} {brief}"))
    for text in _log_notes(log, r):
        warn(text)


def _kinds(kinds: list[str], most: int = 12) -> str:
    """The event kinds a log has, bounded (a forged log may hold many)."""
    text = ", ".join(_short(k) for k in kinds[:most])
    return text + (f", +{len(kinds) - most} more" if len(kinds) > most else "")


@main.command()
@click.argument("logs", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option(
    "--host",
    default="127.0.0.1",
    show_default=True,
    help="address to serve on (0.0.0.0 exposes the viewer to the network)",
)
@click.option(
    "--port",
    type=click.IntRange(0, 65535),
    default=8080,
    show_default=True,
    help="port (the next free one if taken; 0 = any free port)",
)
@click.option(
    "--speed",
    type=click.Choice(SPEEDS),
    default=DEFAULT_SPEED,
    show_default=True,
    help="initial playback speed (simulated s per wall-clock s)",
)
@click.option(
    "--timeout",
    type=click.FloatRange(min=0, min_open=True),
    metavar="SECONDS",
    help="stop serving after this long (default: until Ctrl-C)",
)
def view(logs, host, port, speed, timeout):
    """Replay LOGS in the browser (Viser): 3-D scene, timeline, events, plots. Several logs
    are overlaid in step (e.g. optimised vs unoptimised)."""
    from replay.viewer import Viewer, ViewerError

    from replay.viewer.guard import is_ip

    named = not is_ip(host)
    if not named:
        _warn_if_exposed(host)  # before anything listens
    try:
        viewer = Viewer.open(logs, host=host, port=port, speed=speed)
    except ViewerError as exc:
        fail(str(exc))
    if named:
        _warn_if_exposed(host)  # a name: once it resolved (a bad one stays one line)
    if viewer.port_note:
        note(viewer.port_note)
    for text in viewer.notes:
        warn(text)
    click.echo(f"viewer: {viewer.url}  (Ctrl-C to stop)")
    viewer.wait(timeout)


def _short(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, list):
        return "[" + ", ".join(_short(x) for x in v[:3]) + (", …" if len(v) > 3 else "") + "]"
    if isinstance(v, dict):
        return "{…}"
    text = str(v)  # (a log's value: up to message_bytes long)
    return text if len(text) <= 80 else f"{text[:60]}…({len(text):,} characters)"


@main.group()
def golden():
    """Golden-log regression: `check` compares fresh runs, `update` rewrites them."""


def _goldens(names):
    from replay.golden import ManifestError, load_manifest

    try:
        table = load_manifest()
    except FileNotFoundError:
        fail("no golden manifest shipped (data/golden/manifest.yaml is missing)")
    except ManifestError as exc:
        fail(str(exc))
    unknown = [n for n in names if n not in table]
    if unknown:
        fail(f"unknown golden log {unknown[0]!r} (known: {', '.join(table)})")
    return [table[n] for n in (names or table)]


@golden.command("check")
@click.argument("names", nargs=-1, shell_complete=complete.golden)
@click.option("-q", "--quiet", is_flag=True, help="no progress bars")
def golden_check(names, quiet):
    """Re-run each golden scenario and compare it with its stored log."""
    from replay.golden import check

    failed = 0
    for g in _goldens(names):
        if not g.log.is_file():
            click.echo(
                f"FAIL {g.name}: no golden log {g.log} (run `replay golden update {g.name}`)"
            )
            failed += 1
            continue
        progress = RunProgress(g.name, bars_on(quiet))
        try:
            diffs = check(g, progress=progress)
        except (LogError, ScenarioError) as exc:
            failed += 1
            click.echo(one_line(f"FAIL {g.name}: {exc}"))
            continue
        except Exception as exc:  # noqa: BLE001 - a run that crashes fails its golden only
            failed += 1
            click.echo(one_line(f"FAIL {g.name}: the run failed: {type(exc).__name__}: {exc}"))
            continue
        finally:
            progress.done()
        if diffs:
            failed += 1
            click.echo(f"FAIL {g.name}: first difference: {diffs[0]}")
            for d in diffs[1:]:
                click.echo(f"     also {d}")
        else:
            click.echo(f"ok   {g.name}")
    if failed:
        sys.exit(1)


@golden.command("update")
@click.argument("names", nargs=-1, required=True, shell_complete=complete.golden)
@click.option("-q", "--quiet", is_flag=True, help="no progress bars")
def golden_update(names, quiet):
    """Rewrite golden logs; commit them with the reason in the message."""
    from replay.golden import update

    for g in _goldens(names):
        progress = RunProgress(g.name, bars_on(quiet))
        try:
            path = update(g, progress=progress)
        except (LogError, ScenarioError) as exc:
            fail(f"{g.name}: {exc}")
        finally:
            progress.done()
        click.echo(f"updated {path} ({path.stat().st_size / 1024:.0f} KiB)")
    note("commit the golden logs with the reason for the change in the commit message")


@main.command()
@click.option(
    "-o",
    "--out",
    type=click.Path(dir_okay=False),
    help="write it to this file (default: stdout); docs/cli.md says how to hook it to an editor",
)
def schema(out):
    """The scenario format as a JSON Schema (every field with its unit, range and default;
    plug-in types as enums, each plug-in's params), for editors that complete and check YAML."""
    import json

    from replay.scenario.json_schema import scenario_schema

    text = json.dumps(scenario_schema(), indent=1) + "\n"
    if not out:
        click.echo(text, nl=False)
        return
    write_text(Path(out), text, kind="JSON Schema", magic=b"{")
    click.echo(f"wrote {out}")


@main.command()
@click.argument("scenario", type=click.Path(dir_okay=False), shell_complete=complete.scenario)
@click.option(
    "-o", "--out", type=click.Path(dir_okay=False), required=True, help="the URDF file to write"
)
@click.option("--set", "sets", multiple=True, metavar="KEY.PATH=VALUE")
def urdf(scenario, out, sets):
    """Write the robot of SCENARIO's plant as URDF (what the simulator loads), e.g. for
    Foxglove, RViz or yourdfpy."""
    sc = _load(scenario, sets)
    cls = registry.load("plant", sc.plant.type)
    describe = getattr(cls, "robot_description", None)  # the URDF text, or None
    if describe is None or describe is getattr(Plant, "robot_description", None):
        fail(f"{scenario}: plant {sc.plant.type!r} has no URDF (its robot is not a URDF model)")
    try:
        plant = cls(sc.plant.params, dt=1.0 / sc.timing.physics_rate, rng=np.random.default_rng(0))
    except _REFUSED as exc:
        fail(_refusal(scenario, exc))
    try:
        text = plant.robot_description()
    finally:
        plant.close()
    if not text:
        fail(f"{scenario}: plant {sc.plant.type!r} has no URDF")
    write_text(Path(out), text, kind="URDF", magic=b"<?xml")
    click.echo(f"wrote {out}")


@main.command()
@click.argument("name", shell_complete=complete.scenario)
@click.option(
    "-o", "--out", type=click.Path(dir_okay=False), help="copy it to this file (default: stdout)"
)
def show(name, out):
    """Print the scenario NAME (a shipped one by name, e.g. stick_3step, or a file), or copy it
    to FILE as a start for your own. A copy's ``extends:`` of a shipped scenario still resolves
    (a bare name is a shipped scenario), so ``extends: stick_3step`` and one changed value is a
    complete scenario."""
    path = Path(find_scenario(name))
    if not path.is_file():
        fail(f"no scenario {name!r}: `replay list` names the shipped ones")
    text = path.read_text(encoding="utf-8")
    if not out:
        click.echo(text, nl=False)
        return
    target = Path(out)
    if target.exists() or target.is_symlink():
        fail(f"will not overwrite {target}: it exists (remove it or give another -o)")
    if target.resolve() == path.resolve():
        fail(f"{target} is the scenario itself")
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        with open(target, "x", encoding="utf-8") as f:
            f.write(text)
    except OSError as exc:
        fail(f"cannot write {target}: {exc.strerror or exc}")
    click.echo(f"wrote {target} (from {path.name}); run it with: replay run {target}")


@main.command()
@click.argument("paper", type=click.Choice(registry.names("paper")))
@click.option(
    "-o", "--out", type=click.Path(dir_okay=False), help="write it to this file (default: stdout)"
)
def layout(paper, out):
    """A Foxglove layout for PAPER's logs (Layout -> Import from file; docs/foxglove.md): 3-D
    scene, camera images, the paper's quantities plotted, the events."""
    from replay.foxglove.layouts import layout_json  # noqa: PLC0415

    try:
        text = layout_json(paper)
    except KeyError as exc:  # a registered paper without a layout
        fail(str(exc.args[0]))
    if not out:
        click.echo(text, nl=False)
        return
    write_text(Path(out), text, kind="Foxglove layout", magic=b"{")
    click.echo(f"wrote {out}")


@main.command()
@click.argument("log", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--web", is_flag=True, help="Rerun's web viewer on 127.0.0.1 instead of the native one"
)
@click.option(
    "--port", type=int, default=9090, show_default=True, help="web viewer port (+1: data)"
)
@click.option("--at", type=float, help="convert the log only up to T seconds")
@click.option("--shot", type=click.Path(dir_okay=False), help="with --web: screenshot to FILE")
def rerun(log, web, port, at, shot):
    """Open LOG in Rerun's viewer with a ready layout, its timeline in simulated seconds (needs
    the extra: pip install 'paper-replay[rerun]'). Every process it starts is stopped when it
    ends (docs/foxglove.md)."""
    from replay.foxglove.rerun_view import RerunError, view  # noqa: PLC0415

    try:
        view(Path(log), web=web, port=port, at=at, shot=Path(shot) if shot else None)
    except RerunError as exc:
        fail(str(exc))


from replay.evaluate import evaluate_command  # noqa: E402
from replay.sweep.commands import register  # noqa: E402  (replay sweep, ablate)

register(main)
main.add_command(evaluate_command)  # replay evaluate (replay/evaluate.py)
for _name in registry.names("commands"):  # installed packages' commands (analysis: figures, ...)
    registry.load("commands", _name)(main)

if __name__ == "__main__":
    main()
