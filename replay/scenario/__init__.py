"""Scenarios: the typed schema and its strict YAML loader."""

from replay.scenario.loader import (
    ScenarioError,
    load_scenario,
    params_from_data,
    resolved_yaml,
    scenario_from_text,
    to_plain,
)
from replay.scenario.schema import (
    ControllerSpec,
    PlantSpec,
    Scenario,
    SensorSpec,
    Stop,
    TaskSpec,
    Timing,
)

__all__ = [
    "ControllerSpec",
    "PlantSpec",
    "Scenario",
    "ScenarioError",
    "SensorSpec",
    "Stop",
    "TaskSpec",
    "Timing",
    "load_scenario",
    "params_from_data",
    "resolved_yaml",
    "scenario_from_text",
    "to_plain",
]
