"""paper-replay: re-run landmark high-speed robotics experiments from YAML scenarios into MCAP logs.

The Python API (:mod:`replay.api`): ``replay.run(scenario, seed=, set=, log=)`` and
``replay.open_log(path)`` return a :class:`~replay.api.Run`; they are imported on first use, so
``import replay`` stays cheap.
"""

__version__ = "0.1.0"

__all__ = ["LogError", "Run", "ScenarioError", "__version__", "open_log", "run"]

_LAZY = {
    "run": "replay.api",
    "open_log": "replay.api",
    "Run": "replay.api",
    "ScenarioError": "replay.scenario",
    "LogError": "replay.log",
}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'replay' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
