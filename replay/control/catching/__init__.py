"""Namiki & Ishikawa, "Robotic Catching Using a Direct Mapping from Visual Information to Motor
Command": the mapping q_d = g o l_c^-1(r_o) (eqs. 6-8, 12), its initial constraint (eqs. 13-14),
the torque/velocity along ball trajectories (eqs. 15-23), the offline optimisation of eq. 25 and
the 1 kHz catching controller. Pure NumPy; no simulator import.
"""

from replay.control.catching.controller import CatchingController, CatchingState, Params
from replay.control.catching.estimator import BallisticEstimator
from replay.control.catching.mapping import CatchGeometry, DirectMapping, Features, PolynomialB
from replay.control.catching.model import ArmModel
from replay.control.catching.optimise import (
    CostRecord,
    Objective,
    OptimResult,
    initial_alpha,
    load_alpha,
    optimise,
    save_alpha,
)
from replay.control.catching.problem import CatchingProblem, ProblemConfig, build_problem
from replay.control.catching.trajectories import ThrowSet, launch_velocity, throw_set

__all__ = [
    "CatchingController",
    "CatchingState",
    "Params",
    "BallisticEstimator",
    "CatchGeometry",
    "DirectMapping",
    "Features",
    "PolynomialB",
    "ArmModel",
    "CostRecord",
    "Objective",
    "OptimResult",
    "initial_alpha",
    "load_alpha",
    "optimise",
    "save_alpha",
    "CatchingProblem",
    "ProblemConfig",
    "build_problem",
    "ThrowSet",
    "launch_velocity",
    "throw_set",
]
