"""Air-table plant for the stick-capture experiment (Higashimori et al. 2007), on Pymunk.

``params`` and ``viewer_scene`` import no simulator; ``AirTablePlant`` (Pymunk) is imported when
first asked for.
"""

from plants.airtable.params import (
    HandParams,
    InitialParams,
    Params,
    SolverParams,
    StickParams,
    ThrowParams,
)

__all__ = [
    "AirTablePlant",
    "Params",
    "StickParams",
    "InitialParams",
    "HandParams",
    "SolverParams",
    "ThrowParams",
]


def __getattr__(name: str):
    if name == "AirTablePlant":
        from plants.airtable.plant import AirTablePlant

        return AirTablePlant
    raise AttributeError(f"module 'plants.airtable' has no attribute {name!r}")
