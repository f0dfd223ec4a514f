"""``python -m tools.bench.log_costs [SCENARIO ...]``: what a log message costs, in one process.

The messages of a short run of each scenario are kept (deep copies, as the observers saw them),
then written again and again, CPU time (``time.process_time``), best of ``--repeat``: the JSON
encoding alone; the MCAP records of the encoded bytes through foxglove-sdk's MCAP writer
as the log configures it (``replay.log.chunks``: zstd chunks); and the whole ``LogWriter.write``
as the runner calls it (a log's opening and closing, once a run, apart). Nothing here is a
test.
"""

from __future__ import annotations

import argparse
import copy
import io
import tempfile
import time
from pathlib import Path
from typing import Any

import foxglove

from replay.log.chunks import mcap_writer
from replay.log.writer import LogWriter, encode
from replay.resources import scenario_dir

DEFAULT = ["stick_3step", "catch_optimised", "grasp_hexahedron"]
CHUNK = 256 * 1024  # LogWriter's


def capture(scenario: str, duration: float) -> list[tuple[str, object, int]]:
    """(topic, payload, t_ns) of every message of a run of ``duration`` simulated seconds."""
    from replay.runner import Runner
    from replay.scenario import load_scenario

    path = Path(scenario)
    if not path.is_file():
        path = scenario_dir() / f"{scenario}.yaml"
    sc = load_scenario(path, sets=[f"timing.duration={duration}"])
    seen: list[tuple[str, object, int]] = []
    runner = Runner(sc, observers=(lambda topic, p, t: seen.append((topic, copy.deepcopy(p), t)),))
    with tempfile.TemporaryDirectory() as tmp:
        runner.run(Path(tmp) / "capture.mcap")
    return seen


def _best(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        c0 = time.process_time()
        fn()
        best = min(best, time.process_time() - c0)
    return best


def costs(messages: list[tuple[str, object, int]], repeat: int = 5) -> dict[str, float]:
    """CPU seconds a message of each stage (best of ``repeat``)."""
    encoded = [(topic, encode(topic, p), t) for topic, p, t in messages]

    def encoding() -> None:
        for topic, p, _ in messages:
            encode(topic, p)

    def records() -> None:
        context = foxglove.Context()
        w = mcap_writer(io.BytesIO(), context, chunk_size=CHUNK)
        channels: dict[str, Any] = {}
        for topic, data, t in encoded:
            log = channels.get(topic)
            if log is None:
                schema = foxglove.Schema(name=topic, encoding="jsonschema", data=b"{}")
                log = channels[topic] = context._create_channel(
                    topic, message_encoding="json", schema=schema
                ).log  # (as LogWriter makes its channels)
            log(data, t)
        w.close()

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "x.mcap"

        def whole() -> None:
            with LogWriter(path) as log:
                for topic, p, t in messages:
                    log.write(topic, p, t)

        def empty() -> None:  # a log's opening and closing (once a run: fsync, rename)
            with LogWriter(path):
                pass

        n = max(len(messages), 1)
        out = {
            name: _best(fn, repeat) / n
            for name, fn in (
                ("encode", encoding),
                ("records", records),
                ("write", whole),
            )
        }
        out["open_close"] = _best(empty, repeat)
    out["write"] = max(0.0, out["write"] - out["open_close"] / n)
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenarios", nargs="*", default=DEFAULT)
    ap.add_argument("--duration", type=float, default=0.5, help="simulated s captured")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    for scenario in args.scenarios:
        messages = capture(scenario, args.duration)
        c = costs(messages, args.repeat)
        size = sum(len(encode(t, p)) for t, p, _ in messages) / max(len(messages), 1)
        print(
            f"log messages of {scenario} ({len(messages)} in {args.duration:g} s, {size:.0f} B "
            f"of JSON each), CPU us a message: LogWriter.write {1e6 * c['write']:.2f} = JSON "
            f"{1e6 * c['encode']:.2f} + MCAP records and zstd (foxglove-sdk's writer) "
            f"{1e6 * c['records']:.2f} + the rest; "
            f"opening and closing a log: {1e3 * c['open_close']:.1f} ms",
            flush=True,
        )


if __name__ == "__main__":
    main()
