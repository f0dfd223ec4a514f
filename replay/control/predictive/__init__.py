"""A predict-then-intercept baseline for the catching arm (Kalman filter, an intercept chosen for
reach and palm alignment, a torque-feasible rollout plan). Pure NumPy."""

from replay.control.predictive.controller import Params, PredictiveController
from replay.control.predictive.intercept import Rollout, choose_intercept, solve_ik
from replay.control.predictive.kalman import BallKalman
from replay.control.predictive.trajectory import InterceptPlan, Quintic

__all__ = [
    "Params",
    "PredictiveController",
    "Rollout",
    "choose_intercept",
    "solve_ik",
    "BallKalman",
    "InterceptPlan",
    "Quintic",
]
