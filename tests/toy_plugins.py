"""A tiny plant, sensor and controller to test the core without any paper: a point mass on a
line pushed by a force, seen by a position sensor, driven by a PD controller."""

from __future__ import annotations

from dataclasses import dataclass

from replay import registry
from replay.interfaces import Controller, Occurrence, Plant, Sensor
from replay.params import param
from replay.scene import Scene, Sphere


@dataclass
class ToyPlantParams:
    mass: float = param(1.0, unit="kg", gt=0, doc="the mass")
    x0: float = param(0.0, unit="m", doc="start")
    wall: float = param(10.0, unit="m", doc="a wall event fires when x passes it")
    blow_up_at: float = param(-1.0, unit="s", doc="make the state NaN at this time (<0: never)")


class ToyPlant(Plant):
    Params = ToyPlantParams

    def __init__(self, params, *, dt, rng):
        super().__init__(params, dt=dt, rng=rng)
        self.x, self.v, self.f, self.t = params.x0, 0.0, 0.0, 0.0
        self.events = []
        self.hit = False

    def apply(self, command):
        self.f = float(command)

    def step(self):
        self.v += self.f / self.params.mass * self.dt
        self.x += self.v * self.dt
        self.t += self.dt
        if 0 <= self.params.blow_up_at <= self.t:
            self.x = float("nan")
        if self.x >= self.params.wall and not self.hit:
            self.hit = True
            self.events.append(Occurrence("collision", {"x": self.x}))

    def truth(self, t):
        return {"/toy/state": {"t": t, "x": self.x, "v": self.v}}

    def scene(self):
        return Scene([Sphere("ball", (self.x, 0.0, 0.0), 0.1)])

    def spec(self):
        return {"mass": self.params.mass}

    def pop_events(self):
        out, self.events = self.events, []
        return out


@dataclass
class ToySensorParams:
    noise: float = param(0.0, unit="m", ge=0)


class ToySensor(Sensor):
    Params = ToySensorParams
    topic = "/toy/measured"

    def measure(self, t, scene):
        x = scene.get("ball").position[0]
        return {"t": t, "x": x + self.params.noise * float(self.rng.standard_normal())}


@dataclass
class ToyControllerParams:
    target: float = param(1.0, unit="m")
    kp: float = param(100.0, unit="N/m", ge=0)
    kd: float = param(20.0, unit="N*s/m", ge=0)


class ToyController(Controller):
    Params = ToyControllerParams

    def __init__(self, params, *, spec):
        super().__init__(params, spec=spec)
        self.seen = []  # (t_now, t_captured)
        self.last = None
        self.done = False
        self.out = []

    def update(self, t, measurements):
        for _, m in measurements:
            self.seen.append((t, m["t"]))
            v = (
                0.0
                if self.last is None
                else (m["x"] - self.last[1]) / max(m["t"] - self.last[0], 1e-9)
            )
            self.last = (m["t"], m["x"], v)
        if self.last is None:
            return 0.0
        if (
            not self.done
            and abs(self.last[1] - self.params.target) < 1e-3
            and abs(self.last[2]) < 1e-3
        ):
            self.done = True
            self.out.append(Occurrence("arrived", {"x": self.last[1]}))
        return self.params.kp * (self.params.target - self.last[1]) - self.params.kd * self.last[2]

    def intent(self):
        return {"target": self.params.target}

    def pop_events(self):
        out, self.out = self.out, []
        return out


def install():
    registry.register("plant", "toy", ToyPlant)
    registry.register("sensor", "toy_sensor", ToySensor)
    registry.register("controller", "toy_pd", ToyController)
