"""What a run writes for Foxglove and Rerun (replay/foxglove/topics.py), fed by the log's
observer of the runner's step records (:class:`replay.observers.LogObserver`):
the URDF at the start, ``/tf`` + ``/scene`` + ``/joint_states`` at ``timing.frame_rate``, each
camera frame of a sensor with ``log_images``, each event as a ``/log`` line."""

from __future__ import annotations

from replay.foxglove.topics import FoxgloveTopics
from replay.log.writer import encode
from replay.messages import TOPIC_EVENTS, Event
from replay.scene import Scene


class RunTopics:
    def __init__(self, log, plant, sensors) -> None:
        """``sensors``: (name, sensor) pairs; those whose params say ``log_images`` and that
        have ``frame_images()`` get their frames logged."""
        self.out = FoxgloveTopics(log)
        self.plant = plant
        self.imaging = {
            name
            for name, sensor in sensors
            if getattr(sensor.params, "log_images", False) and hasattr(sensor, "frame_images")
        }

    def start(self, t_ns: int) -> None:
        urdf = self.plant.robot_description()
        if urdf:
            self.out.robot_description(urdf, t_ns)

    def frame(self, scene: Scene, t_ns: int) -> None:
        """The plant now: its bodies' and links' frames, its primitives, its joints."""
        self.out.transforms(self.plant.frames(), t_ns, bodies=scene.primitives)
        self.out.scene(scene.primitives, t_ns)
        joints = self.plant.joints()
        if joints is not None:
            names, position, velocity, effort = joints
            self.out.joint_states(names, position, velocity, effort, t_ns)

    def sensor(self, name: str, sensor, t_ns: int) -> None:
        if name in self.imaging:
            self.out.images(name, sensor.frame_images(), t_ns)

    def event(self, event: Event, t_ns: int) -> None:
        self.out.event(event.kind, event.data, encode(TOPIC_EVENTS, event.data).decode(), t_ns)
