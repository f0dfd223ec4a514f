"""Write a plug-in plant (and a controller for it), register it, run a scenario with it.

    .venv/bin/python examples/03_write_a_plugin_plant.py [OUT_DIR]

A cart on a rail (1-D, no friction) pushed by a force, an encoder, and a PD controller that
brings it to a target. In a package, the same classes are registered in its ``pyproject.toml``:

    [project.entry-points."paper_replay.plants"]
    cart = "my_package.cart:CartPlant"
    [project.entry-points."paper_replay.sensors"]
    cart_encoder = "my_package.cart:CartEncoder"
    [project.entry-points."paper_replay.controllers"]
    cart_pd = "my_package.cart:CartPD"

(and a viewer scene under ``paper_replay.viewer_scenes``, docs/viewer.md); here they are
registered in this process only (``registry.register``), as a notebook or a test would.
"""

from __future__ import annotations

import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from replay import registry
from replay.interfaces import Controller, Occurrence, Plant, Sensor
from replay.log import LogReader
from replay.params import param
from replay.runner import Runner
from replay.scenario import scenario_from_text
from replay.scene import Scene, Sphere

TOPIC_CART_STATE = "/cart/state"  # new topics: add freely, rename none
TOPIC_CART_ENCODER = "/cart/encoder"


# ---------------------------------------------------------------------------- the plant
@dataclass
class CartParams:
    """Checked by the scenario loader (``replay validate``) before anything runs."""

    mass: float = param(2.0, unit="kg", gt=0, doc="the cart's mass")
    x0: float = param(0.0, unit="m", doc="initial position")
    max_force: float = param(20.0, unit="N", gt=0, doc="actuator limit |F|")


@dataclass(frozen=True)
class CartSpec:
    """What a controller may know of the plant: nominal values, no simulator state."""

    mass: float
    max_force: float


@dataclass
class CartState:
    t: float
    x: float
    v: float


class CartPlant(Plant):
    """A cart on a frictionless rail, integrated here (a real plant would step a simulator)."""

    Params = CartParams
    spec_type = CartSpec  # typed ports (common.md): what spec() gives ...
    command_types = (float,)  # ... and what apply() takes
    description = "a cart on a rail pushed by a force (example)"

    def __init__(self, params: CartParams, *, dt: float, rng: np.random.Generator) -> None:
        super().__init__(params, dt=dt, rng=rng)
        self.x, self.v, self.force, self.t = params.x0, 0.0, 0.0, 0.0
        self._events: list[Occurrence] = []
        self._limited = False

    def apply(self, command: float) -> None:
        f = float(command)
        limited = abs(f) > self.params.max_force
        if limited and not self._limited:
            self._events.append(Occurrence("force_limit", {"commanded": f}))
        self._limited = limited
        self.force = float(np.clip(f, -self.params.max_force, self.params.max_force))

    def step(self) -> None:  # semi-implicit Euler: v then x
        self.v += self.force / self.params.mass * self.dt
        self.x += self.v * self.dt
        self.t += self.dt

    def truth(self, t: float) -> dict:
        return {TOPIC_CART_STATE: CartState(t, self.x, self.v)}

    def scene(self) -> Scene:  # what cameras could see
        return Scene(
            [Sphere("cart", (self.x, 0.0, 0.0), 0.05)],
            readings={"cart": {"x": self.x, "v": self.v}},
        )

    def spec(self) -> CartSpec:
        return CartSpec(self.params.mass, self.params.max_force)

    def pop_events(self) -> list[Occurrence]:
        out, self._events = self._events, []
        return out

    def outcome(self, t: float) -> dict:
        return {"x": self.x, "v": self.v}


# ---------------------------------------------------------------------------- a controller
@dataclass
class CartPDParams:
    target: float = param(1.0, unit="m")
    kp: float = param(40.0, unit="N/m", ge=0)
    kd: float = param(15.0, unit="N*s/m", ge=0)


class CartPD(Controller):
    """PD on the encoder's readings: a method sees only what sensors deliver, and the spec."""

    Params = CartPDParams
    spec_type = CartSpec
    command_type = float
    reads = (TOPIC_CART_ENCODER,)

    def __init__(self, params: CartPDParams, *, spec: CartSpec) -> None:
        super().__init__(params, spec=spec)
        self.x = self.v = 0.0

    def update(self, t: float, measurements: list) -> float:
        for _, m in measurements:
            self.x, self.v = m.x, m.v
        p = self.params
        return p.kp * (p.target - self.x) - p.kd * self.v

    def outcome(self, t: float) -> dict:
        err = abs(self.params.target - self.x)
        return {"error": err} if err < 0.01 else {"success": False, "reason": f"{err:.3f} m off"}


# ---------------------------------------------------------------------------- a sensor
@dataclass
class CartEncoderParams:
    noise: float = param(0.0, unit="m", ge=0, doc="standard deviation of the position reading")


@dataclass
class CartReading:
    t: float
    x: float
    v: float


class CartEncoder(Sensor):
    """The cart's own position and speed readings (from the plant's Scene), with noise."""

    Params = CartEncoderParams
    spec_type = CartSpec
    topic = TOPIC_CART_ENCODER

    def measure(self, t: float, scene: Scene) -> CartReading:
        r = scene.readings["cart"]
        return CartReading(
            t, r["x"] + self.params.noise * float(self.rng.standard_normal()), r["v"]
        )


SCENARIO = """
name: cart_example
paper: none
description: a cart brought to x = 1 m
timing: {physics_rate: 1000, duration: 3.0}
plant: {type: cart, params: {mass: 2.0, max_force: 20.0}}
sensors:
  encoder: {type: cart_encoder, rate: 100, latency: 0.01, params: {noise: 0.0001}}
controller: {type: cart_pd, rate: 100, params: {target: 1.0}}
"""


def main(out_dir: Path) -> None:
    registry.register("plant", "cart", CartPlant)
    registry.register("sensor", "cart_encoder", CartEncoder)
    registry.register("controller", "cart_pd", CartPD)
    sc = scenario_from_text(SCENARIO, name="cart_example.yaml")  # validated like a file
    print(f"plant params: {sc.plant.params}")
    result = Runner(sc).run(out_dir / "cart.mcap")
    print(f"wrote {result.path}: {result.messages} messages; events {result.events}")
    print(f"outcome: {result.outcome}")
    states = LogReader(result.path).series(TOPIC_CART_STATE)
    print(
        f"{TOPIC_CART_STATE}: {len(states)} messages, x = {states[0]['x']:.3f} -> "
        f"{states[-1]['x']:.3f} m"
    )


if __name__ == "__main__":
    if len(sys.argv) > 1:
        main(Path(sys.argv[1]))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            main(Path(tmp))
