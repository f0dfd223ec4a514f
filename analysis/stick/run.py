"""One stick run's log read for the claims table (Higashimori et al. 2007): its collisions,
outcome, when the stick stopped, and the plant's and controller's parameters it ran with."""

from __future__ import annotations

import copy

import numpy as np

from analysis.series import arrays, events
from plants.airtable.params import Params as AirTableParams
from replay.log import LogReader
from replay.messages import TOPIC_STICK_STATE
from analysis.runs import typed_scenario


def collision(log: LogReader, index: int) -> dict | None:
    for e in events(log, "collision"):
        if e["data"].get("index") == index:
            return e
    return None


def collisions(log: LogReader) -> list[dict]:
    return sorted(events(log, "collision"), key=lambda e: e["data"]["index"])


def time_stopped(log: LogReader, speed: float = 0.02) -> float | None:
    """First time after which the stick's speed stays below ``speed`` m/s."""
    s = arrays(log, TOPIC_STICK_STATE, ["vx", "vy"])
    moving = np.hypot(s["vx"], s["vy"]) >= speed
    if not len(moving) or moving[-1]:
        return None
    last = np.nonzero(moving)[0]
    return float(s["t"][last[-1] + 1]) if len(last) else float(s["t"][0])


def plant_params(log: LogReader) -> AirTableParams:
    plant = typed_scenario(log).plant.params  # typed by the loader
    assert isinstance(plant, AirTableParams)
    return plant


def outcome(log: LogReader) -> dict:
    ev = events(log, "outcome")
    return ev[-1]["data"] if ev else {}


def controller_params(log: LogReader) -> dict:
    return copy.deepcopy(log.scenario_config())["controller"].get("params", {}) or {}
