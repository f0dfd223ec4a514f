"""Sweeps: many variants of one scenario, run in parallel (a local pool or Ray), one table.

- :mod:`.spec`: ``--grid``/``--random`` and sweep files (``sweeps/NAME.yaml``);
- :mod:`.variants`: expansion, the hash key (resolved scenario + seed + code version);
- :mod:`.worker`: one variant -> one row (never raises);
- :mod:`.executors`: the local process pool and Ray;
- :mod:`.engine`: skip what the table holds, run the rest, rewrite the table as rows arrive;
- :mod:`.commands`: ``replay sweep``, ``replay ablate``, ``replay report``.
"""
