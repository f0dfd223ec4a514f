"""A predict-then-intercept baseline for the catching arm (Kalman filter, ballistic catch point,
inverse kinematics, a re-planned time-parameterised joint trajectory). Pure NumPy."""

from replay.control.predictive.controller import Params, PredictiveController
from replay.control.predictive.kalman import BallKalman, first_crossing
from replay.control.predictive.trajectory import Quintic

__all__ = ["Params", "PredictiveController", "BallKalman", "first_crossing", "Quintic"]
