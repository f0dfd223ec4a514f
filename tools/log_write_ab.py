"""What the compiled JSON message path saves inside a real run: one process, runs alternating
between LogWriter.write as it is (``_chunk.c`` ``json`` first) and its Python path alone
(encode, the channel, the record), the CPU time of every write() call and of the whole run
(``time.process_time``; two readings a message are included in the write() figure). Same
messages either way (tests/replay/log/test_json_path.py: same bytes).

    .venv/bin/python tools/log_write_ab.py scenarios/catch_optimised.yaml [runs]
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

from replay.log import writer
from replay.runner import Runner
from replay.scenario import load_scenario


def main(path: str, runs: int = 5) -> None:
    sc = load_scenario(path)
    clock = time.process_time
    mode, spent = ["compiled"], [0.0, 0]
    init, write = writer.LogWriter.__init__, writer.LogWriter.write

    def patched_init(self, *args, **kw):
        init(self, *args, **kw)
        if mode[0] == "python":
            self._json = lambda topic, payload, t_ns: False  # every message by the Python path

    def timed_write(self, topic, payload, t_ns):
        c0 = clock()
        write(self, topic, payload, t_ns)
        spent[0] += clock() - c0
        spent[1] += 1

    results: dict[str, list[tuple[float, float, float]]] = {"python": [], "compiled": []}
    with tempfile.TemporaryDirectory() as tmp:
        Runner(sc).run(Path(tmp) / "warm-up.mcap")
        writer.LogWriter.__init__ = patched_init  # type: ignore[method-assign]
        writer.LogWriter.write = timed_write  # type: ignore[method-assign]
        try:
            for i in range(runs):
                for m in results:
                    mode[0], spent[:] = m, [0.0, 0]
                    c0 = clock()
                    r = Runner(sc).run(Path(tmp) / f"{m}{i}.mcap")
                    total = clock() - c0
                    results[m].append((total / r.t_end, spent[0] / r.t_end, spent[0] / spent[1]))
        finally:
            writer.LogWriter.__init__ = init  # type: ignore[method-assign]
            writer.LogWriter.write = write  # type: ignore[method-assign]
    for m, v in results.items():
        run_s, write_s, per = (statistics.median(x[k] for x in v) for k in range(3))
        print(
            f"{sc.name} {m:8s}: run {run_s:.3f} CPU s per simulated s; write() "
            f"{1e3 * write_s:.1f} ms per simulated s = {1e6 * per:.2f} us a message "
            f"(median of {runs})"
        )


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 5)
