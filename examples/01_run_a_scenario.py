"""Run a scenario from Python: load (and validate) it, override fields, run it, read the verdict.

    .venv/bin/python examples/01_run_a_scenario.py [OUT_DIR]

The same as ``replay run scenarios/stick_3step.yaml --set timing.duration=0.3 -o OUT``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from plants.airtable import Params as AirTableParams
from replay.runner import Runner
from replay.scenario import ScenarioError, load_scenario

ROOT = Path(__file__).resolve().parents[1]


def main(out_dir: Path) -> None:
    try:
        # --set overrides are "key.path=value" strings, the value read as YAML
        sc = load_scenario(
            ROOT / "scenarios" / "stick_3step.yaml", sets=["timing.duration=0.3"], seed=0
        )
    except ScenarioError as exc:  # one line: file:line:col, the field, what was expected
        sys.exit(f"error: {exc}")
    method = sc.controller.type if sc.controller else f"tasks {sorted(sc.tasks)}"
    print(
        f"scenario {sc.name} ({sc.paper}): plant {sc.plant.type}, controller "
        f"{method}, sensors {sorted(sc.sensors)}"
    )
    p = sc.plant.params  # the plant's own typed Params, every default filled in
    assert isinstance(p, AirTableParams)
    print(f"the stick's mass: {p.stick.mass} kg, restitution {p.stick.restitution}")
    result = Runner(sc).run(out_dir / f"{sc.name}.mcap")
    print(
        f"wrote {result.path}: {result.messages} messages, {result.steps} steps, "
        f"t_end = {result.t_end:.3f} s, stopped by {result.stopped_by}"
    )
    print(f"events: {result.events}")
    print(
        f"outcome: success={result.outcome.get('success')} reason={result.outcome.get('reason')!r}"
    )


if __name__ == "__main__":
    if len(sys.argv) > 1:
        main(Path(sys.argv[1]))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            main(Path(tmp))
