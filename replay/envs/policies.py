"""The papers' methods as policies: the scenario's own controller (built by the runner from the
registry, as in ``replay run``) asked for the command, which goes through the action vector."""

from __future__ import annotations

from typing import Any

import numpy as np


class PaperPolicy:
    """``policy(observation, info) -> action`` of the scenario's method. Its episodes need the
    method in the runner (``reset_options``), where its events, telemetry and verdict are logged
    as in ``replay run``; it reads the measurements as delivered (``info["measurements"]``)."""

    reset_options = {"method": True}

    def __init__(self, env: Any) -> None:
        self.env = env.unwrapped

    def __call__(self, observation: Any, info: dict) -> np.ndarray:
        env = self.env
        command = env.method.update(info["t"], info["measurements"])
        return env.layout.action_of(command, env.held)


def paper(env: Any) -> PaperPolicy:
    """The policy factory of ``replay evaluate`` for the paper's method."""
    return PaperPolicy(env)
