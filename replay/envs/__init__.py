"""The papers' tasks as Gymnasium environments (``pip install paper-replay[envs]``): importing
this package registers

- ``paper_replay/Catch-v0``: ``catch_optimised`` (Namiki & Ishikawa 2003), 1 ms steps;
- ``paper_replay/Grasp-v0``: ``grasp_hexahedron`` (Namiki et al. 1999), 1 ms steps;
- ``paper_replay/StickCapture-v0``: ``stick_3step`` (Higashimori et al. 2007), 1 ms steps;
- ``paper_replay/Scenario-v0``: any scenario, ``gymnasium.make(..., scenario="name or path")``.

``gymnasium.make("replay.envs:paper_replay/Catch-v0")`` imports it first. Keyword arguments
(``set=``, ``truth=``, ``log=``) are :class:`replay.envs.env.ScenarioEnv`'s. docs/envs.md.
"""

from __future__ import annotations

TASKS = {
    "catch": ("paper_replay/Catch-v0", "catch_optimised"),
    "grasp": ("paper_replay/Grasp-v0", "grasp_hexahedron"),
    "stick": ("paper_replay/StickCapture-v0", "stick_3step"),
}
GENERIC = "paper_replay/Scenario-v0"
_ENTRY = "replay.envs.env:ScenarioEnv"


def register() -> None:
    """Register the environments with Gymnasium (done on import; again: nothing new)."""
    import gymnasium

    for env_id, scenario in TASKS.values():
        if env_id not in gymnasium.registry:
            gymnasium.register(env_id, entry_point=_ENTRY, kwargs={"scenario": scenario})
    if GENERIC not in gymnasium.registry:
        gymnasium.register(GENERIC, entry_point=_ENTRY)


try:
    register()
except ImportError:  # gymnasium absent: replay.envs.env says so when used
    pass
