"""A simple non-paper policy against the paper's method, on the same held-out throws, through the
Gymnasium environment (``pip install 'paper-replay[envs]'``):

    .venv/bin/python examples/05_evaluate_a_policy.py [N]

The same as ``cd examples && replay evaluate my_policy:catch --task catch --n N``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent))  # my_policy beside this file

from replay.evaluate import evaluate, input_set  # noqa: E402

n = int(sys.argv[1]) if len(sys.argv) > 1 else 5
throws = input_set("held-out", "catch", n)  # analysis/input_sets.py: perturbed 8-10 m/s throws
for tally in evaluate("my_policy:catch", "catch", throws):
    lo, hi = tally.interval()
    print(f"{tally.name}: {tally.wins}/{tally.n} caught, Wilson 95 % [{lo:.2f}, {hi:.2f}]")
