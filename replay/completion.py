"""Shell completion of the command line's arguments (docs/cli.md): shipped scenario names (then
files), golden log names, ablation names. Each is click's ``shell_complete`` callback."""

from __future__ import annotations

from click.shell_completion import CompletionItem

from replay.resources import scenario_dir


def scenario(ctx, param, incomplete: str) -> list[CompletionItem]:
    """A SCENARIO: the shipped scenarios' names, then files."""
    names = sorted(p.stem for p in scenario_dir().glob("*.yaml") if p.stem.startswith(incomplete))
    return [CompletionItem(n) for n in names] + [CompletionItem(incomplete, type="file")]


def golden(ctx, param, incomplete: str) -> list[str]:
    from replay.golden import ManifestError, load_manifest

    try:
        return [n for n in load_manifest() if n.startswith(incomplete)]
    except (OSError, ManifestError):
        return []


def ablation(ctx, param, incomplete: str) -> list[str]:
    from replay.sweep import ablations

    return [n for n in ablations.names() if n.startswith(incomplete)]
