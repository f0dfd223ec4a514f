"""A scenario as a Gymnasium environment, over the runner's own loop (``Runner.sense`` /
``Runner.step(command)``): one environment step is one control period of the scenario.

``reset(seed)`` builds the run of the scenario with that seed (as ``replay run --seed``), and
``reset(seed, options={"set": [...]})`` that episode's run with more overrides (``--set`` strings
or a mapping, applied after the environment's own: another throw, another human path); each
step the action is the plant's command (``replay.envs.spaces``), the plant runs to the next
control step and the observation is what the controller would receive then. The episode ends
as ``replay run`` ends: ``terminated`` after a stopping event of the scenario (``stop.on_events``,
e.g. a catch, a miss, a capture, plus ``stop.after``) or an error, ``truncated`` at
``timing.duration``; then ``info["outcome"]`` is the physics verdict the run logs, and the reward
is 1.0 for its ``success``, else 0.0 (0.0 on every other step); with ``shaped=True`` each step
adds minus the task's hand-object distance times the step (``replay.envs.rewards``).

Without the scenario's method in the loop (the default) nothing of it runs: no plan, no method
events, and the verdict is the plant's alone. ``reset(options={"method": True})`` keeps it in
the runner for its events, telemetry and its side of the verdict (for :class:`PaperPolicy`,
which asks it for the command).
"""

from __future__ import annotations

import os
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from replay.api import _scenario, _sets
from replay.envs.rewards import gap
from replay.envs.spaces import ActionLayout, action_layout, numbers, payload_length
from replay.interfaces import Controller
from replay.log import NonFiniteValueError
from replay.runner import RunResult, Runner
from replay.scenario import Scenario

_BOUND = np.finfo(np.float64).max  # observation boxes: any finite value


class _NoMethod(Controller):
    """The runner's controller when the policy is outside: asked for nothing."""

    def __init__(self) -> None:
        super().__init__(None, spec=None)

    def update(self, t: float, measurements: list) -> None:
        return None


class ScenarioEnv(gymnasium.Env):
    """Any scenario as an environment: ``scenario`` a shipped scenario's name, a file or a
    mapping (as :func:`replay.run`), ``set`` its overrides, ``truth=True`` adds the plant's
    ground truth to the observation (``"truth/<topic>"``, as logged), ``log`` a path (``{seed}``
    replaced) to keep each episode's MCAP log, as ``replay run -o`` writes it; ``shaped=True``
    adds the dense reward of :mod:`replay.envs.rewards` to the sparse one."""

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(
        self,
        scenario: Any,
        *,
        set: Any = None,  # noqa: A002 - the CLI's --set
        truth: bool = False,
        log: str | os.PathLike[str] | None = None,
        shaped: bool = False,
    ) -> None:
        self._source, self._set = scenario, _sets(set)
        self.truth, self.shaped = truth, shaped
        self.log = os.fspath(log) if log is not None else None
        sc = self._scenario(None)
        self.scenario_name, self.seed0 = sc.name, sc.seed
        probe = Runner(sc)
        try:
            # what a policy may know, as a controller does: the nominal robot and object
            self.plant_spec = probe.plant.spec()
            command_type = type(probe.plant).command_types[0]
            self.layout: ActionLayout = action_layout(command_type, self.plant_spec)
            self._sizes = self._observation_sizes(probe)
            if shaped and gap(probe.plant.truth(0.0)) is None:
                raise ValueError(
                    f"{sc.name}: no shaped reward for its plant (replay.envs.rewards: an arm"
                    " with an object, the air table)"
                )
        finally:
            probe.plant.close()
        self.action_space = spaces.Box(self.layout.low, self.layout.high, dtype=np.float64)
        self.observation_space = spaces.Dict(
            {
                key: spaces.Box(-_BOUND, _BOUND, shape=(n,), dtype=np.float64)
                for key, n in self._sizes.items()
            }
        )
        self.dt = probe.ctrl_div / sc.timing.physics_rate  # s: one step, the control period
        self.runner: Runner | None = None
        self.result: RunResult | None = None

    # -- what the environment is made of ---------------------------------------------------
    def _scenario(self, seed: int | None, episode: Any = None) -> Scenario:
        """The scenario with the environment's overrides, then the episode's (``episode``)."""
        return _scenario(self._source, self._set + _sets(episode), seed)

    def _observation_sizes(self, probe: Runner) -> dict[str, int]:
        """``{"time": 1, topic: 1 + n, ...}`` from the sensors' first measurements."""
        sizes = {"time": 1}
        scene = probe.plant.scene()
        for _, sensor, _, _ in probe.sensors:
            sizes[sensor.topic] = 1 + payload_length(sensor.topic, sensor.measure(0.0, scene))
        if self.truth:
            for topic, payload in probe.plant.truth(0.0).items():
                if not isinstance(payload, list):
                    sizes["truth/" + topic] = len(numbers(payload))
        return sizes

    @property
    def method(self) -> Controller:
        """The scenario's own controller of this episode (``options={"method": True}``)."""
        if self.runner is None or isinstance(self.runner.controller, _NoMethod):
            raise RuntimeError(
                "the method is in the loop only after reset(options={'method': True})"
            )
        return self.runner.controller

    # -- the Gymnasium API -----------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self._close_run()
        if seed is None:
            seed = int(self.np_random.integers(2**31))
        options = options or {}
        sc = self._scenario(seed, options.get("set"))
        self.runner = runner = Runner(sc)
        if not options.get("method", False):
            runner.controller = _NoMethod()  # type: ignore[assignment]  # (a Controller too)
        self.result = None
        self._obs = {key: np.zeros(n) for key, n in self._sizes.items()}
        for key in self._sizes:
            if key.startswith("/"):
                self._obs[key][0] = -1.0  # nothing delivered yet
        runner.start(self.log.replace("{seed}", str(seed)) if self.log else None)
        self.held: np.ndarray | None = None  # the last action applied
        return self._observe(), self._info()

    def step(self, action):
        runner = self.runner
        if runner is None or self.result is not None:
            raise RuntimeError("step() before reset() or after the episode ended")
        a = np.asarray(action, dtype=np.float64)
        shaped = 0.0
        try:
            command = self.layout.command_of(a)
            runner.step(command if command is not None else [])  # ([]: none, not the method's)
            self.held = a
            while not runner.done and runner.k % runner.ctrl_div:
                runner.step()
            if self.shaped:
                shaped = -self.dt * (gap(runner.plant.truth(runner.k / runner.rate)) or 0.0)
        except NonFiniteValueError as exc:
            self.result = runner.fail(exc)
        if self.result is None and runner.done:
            self.result = runner.finish()
        obs = self._observe()
        if self.result is None:
            return obs, shaped, False, False, self._info()
        outcome = self.result.outcome
        stopped = self.result.stopped_by
        info = {**self._info(), "outcome": outcome, "result": self.result}
        reward = (1.0 if outcome.get("success") else 0.0) + shaped
        return obs, reward, stopped != "duration", stopped == "duration", info

    def close(self) -> None:
        self._close_run()

    # -- the observation ---------------------------------------------------------------------
    def _observe(self) -> dict[str, np.ndarray]:
        runner = self.runner
        assert runner is not None
        self._delivered = runner.sense() if self.result is None else []
        t = runner.k / runner.rate
        obs = self._obs
        obs["time"][0] = t
        for topic, payload in self._delivered:
            values = numbers(payload)
            if topic in obs and len(values) == obs[topic].shape[0]:  # ("[]": nothing measured)
                obs[topic][:] = values
        if self.truth:
            for topic, payload in runner.plant.truth(t).items():
                key = "truth/" + topic
                if key in obs:
                    obs[key][:] = numbers(payload)
        return {key: v.copy() for key, v in obs.items()}

    def _info(self) -> dict[str, Any]:
        """``t`` (s) and ``measurements``: the (topic, payload) delivered at this step."""
        runner = self.runner
        assert runner is not None
        return {"t": runner.k / runner.rate, "measurements": list(self._delivered)}

    def _close_run(self) -> None:
        """An episode left unfinished (reset or close before its end) is closed as an
        interrupted run: its log kept as ``STEM.interrupted.mcap``, never as a finished one."""
        if self.runner is not None and self.result is None:
            self.result = self.runner.interrupt()
