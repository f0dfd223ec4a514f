"""Air-table plant for the stick-capture experiment (Higashimori et al. 2007), on Pymunk."""

from plants.airtable.params import (HandParams, InitialParams, Params, SolverParams,
                                    StickParams)
from plants.airtable.plant import AirTablePlant

__all__ = ["AirTablePlant", "Params", "StickParams", "InitialParams", "HandParams",
           "SolverParams"]
