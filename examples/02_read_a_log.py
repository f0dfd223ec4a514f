"""Read a run's log: its topics, the scenario it ran (typed again), its events, a time series.

    .venv/bin/python examples/02_read_a_log.py [LOG.mcap]

Without an argument it reads the stored golden log of the stick experiment.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import yaml

from plants.airtable import Params as AirTableParams
from replay.log import LogError, LogReader
from replay.messages import TOPIC_EVENTS, TOPIC_STICK_STATE
from replay.scenario import params_from_data, scenario_from_text

ROOT = Path(__file__).resolve().parents[1]


def main(path: Path) -> None:
    try:
        log = LogReader(path)
    except LogError as exc:
        sys.exit(f"error: {exc}")
    t0, t1 = log.time_range()
    print(f"{path.name}: t = {t0:.3f} .. {t1:.3f} s")
    for topic, n in sorted(log.topic_counts().items()):
        print(f"  {topic:<28} {n:>6} messages")

    # the resolved scenario (every default filled in), typed again by the scenario loader
    info = log.scenario()
    sc = scenario_from_text(info["yaml"], name=f"{path.name}:/scenario")
    print(f"scenario {sc.name} (seed {sc.seed}, code {info['version']}), plant {sc.plant.type}")
    if sc.plant.type == "airtable":
        # or only the plant's params, without the other plug-ins: params_from_data
        plain = yaml.safe_load(info["yaml"])
        p = params_from_data(AirTableParams, plain["plant"]["params"], "plant.params")
        print(
            f"  stick: L = {p.stick.length} m, e = {p.stick.restitution}, mu = {p.stick.friction}"
        )

    for e in log.series(TOPIC_EVENTS):
        print(f"  event t = {e['t']:.4f} s  {e['kind']}")

    if TOPIC_STICK_STATE in log.topic_counts():
        st = log.series(TOPIC_STICK_STATE)
        speed = np.hypot([m["vx"] for m in st], [m["vy"] for m in st])
        print(
            f"stick speed: {speed[0]:.3f} m/s at t = {st[0]['t']:.3f} s, "
            f"{speed[-1]:.3f} m/s at t = {st[-1]['t']:.3f} s"
        )


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "data" / "golden" / "stick_3step.mcap")
