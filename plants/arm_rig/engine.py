"""The engine adapter: what the arm rig (rig.py ``ArmRig``) asks of a physics engine.

The rig owns one adapter (``ArmRig.engine``), built from the rig's public attributes (params,
settings, model, urdf_path, dt, joint_names, active, locked, hand_names) after the rig has
written its URDF; the adapter holds only engine calls and engine settings and reads none of the
rig's private state. States are plain floats (lists or tuples), read once after each step and
shared, never mutated.

The engine is a field of the scenario, ``plant.params.engine: {type: NAME, ...its settings}``
(empty: the plant type's own engine, PyBullet for ``arm_rig``/``grasp_rig``). An engine
is registered by one entry point in the group ``paper_replay.engines``: NAME -> its settings
dataclass (imports no engine), whose ``type`` field is NAME, whose fields are the engine's
settings (checked as any params are) and whose class attributes ``arm`` and ``grasp`` name its
adapters (``module:Class``) for the arm rig and the grasping rig.
"""

from __future__ import annotations

import importlib
from functools import cache
from importlib.metadata import entry_points
from collections.abc import Sequence
from typing import Any, Protocol

from replay.params import ParamError
from replay.scene import Frame

ENGINE_GROUP = "paper_replay.engines"


@cache
def engines() -> dict[str, Any]:
    """The registered engines: name -> its entry point (loaded when first asked for)."""
    return {e.name: e for e in entry_points(group=ENGINE_GROUP)}


def engine_settings(value: Any) -> Any | None:
    """``plant.params.engine`` (a mapping: a scenario's YAML node, a dict from Python or a log)
    as its engine's typed settings; None where empty (the plant type's own engine)."""
    import yaml

    from replay.scenario.loader import build_dataclass, params_from_data

    if isinstance(value, yaml.MappingNode):
        if not value.value:
            return None
        kind = next((v.value for k, v in value.value if k.value == "type"), None)
    elif isinstance(value, dict):
        if not value:
            return None
        kind = value.get("type")
    else:
        raise ParamError("engine", "expected a mapping {type: ENGINE, ...its settings}")
    known = engines()
    if kind not in known:
        names = ", ".join(sorted(known))
        if kind is None:  # (settings set on a scenario that names no engine)
            raise ParamError("engine", f"settings without a type: add type: ENGINE ({names})")
        raise ParamError("engine", f"unknown engine type {kind!r} (known: {names})")
    cls = known[kind].load()
    if isinstance(value, yaml.MappingNode):
        return build_dataclass(value, cls, "plant.params.engine")
    return params_from_data(cls, value, "plant.params.engine")


def own_engine_settings(plant: type) -> Any | None:
    """The engine a rig of class ``plant`` runs where ``plant.params.engine`` is empty: its
    params' own engine (``own_engine``) with that engine's defaults; None for an old plant type
    that brings its own adapter (``Engine``) or a plant with no own engine."""
    own = getattr(getattr(plant, "Params", None), "own_engine", None)
    if not isinstance(own, str) or getattr(plant, "Engine", None) is not None:
        return None
    return engine_settings({"type": own})


# PyBullet's settings as the rig's params held them, flat, before the engine field did (scenarios
# and logs made then): ``migrate_flat_settings`` moves them in
FLAT_PYBULLET = (
    "object_rolling_friction",
    "object_spinning_friction",
    "object_restitution",
    "hand_restitution",
    "contact_stiffness",
    "contact_damping",
    "solver_iterations",
)


def migrate_flat_settings(node: Any, own: str, *, log: bool) -> None:
    """An older ``plant.params`` (a YAML mapping node: a scenario's, or a log's) with PyBullet's
    settings flat in it (``FLAT_PYBULLET``) rewritten in place. Under PyBullet (the engine field's
    type, else the plant type's own engine ``own``) they move into ``engine`` (one given flat
    replaces the engine's own); another engine never used them: a log's are dropped, a
    scenario's are an error naming the first (ParamError)."""
    import yaml

    flat = [(k, v) for k, v in node.value if k.value in FLAT_PYBULLET]
    if not flat:
        return
    rest = [(k, v) for k, v in node.value if k.value not in FLAT_PYBULLET]
    at = next((i for i, (k, _) in enumerate(rest) if k.value == "engine"), None)
    given = rest[at][1] if at is not None else None
    if not (isinstance(given, yaml.MappingNode) and given.value):
        given = None
    types = [] if given is None else [v.value for k, v in given.value if k.value == "type"]
    kind = own if given is None else (types or [""])[0]
    if kind != "pybullet" and not log:
        raise ParamError(
            flat[0][0].value,
            f"a PyBullet setting, not used by engine {kind or '(no type)'}: remove it, or give "
            "it in plant.params.engine with type: pybullet",
        )
    node.value = rest
    if kind != "pybullet":
        return
    if given is None:  # (no engine named: the plant type's own, PyBullet, named now)
        mark, tag = flat[0][0].start_mark, "tag:yaml.org,2002:str"
        name = (yaml.ScalarNode(tag, "type", mark, mark), yaml.ScalarNode(tag, kind, mark, mark))
        given = yaml.MappingNode("tag:yaml.org,2002:map", [name], mark, mark)
        if at is None:
            rest.append((yaml.ScalarNode(tag, "engine", mark, mark), given))
        else:
            rest[at] = (rest[at][0], given)
    own_keys = [k.value for k, _ in given.value]
    for k, v in flat:
        if k.value in own_keys:
            given.value[own_keys.index(k.value)] = (k, v)
        else:
            given.value.append((k, v))


def adapter_class(settings: Any, rig: str) -> type:
    """The adapter class of an engine's ``settings`` for ``rig`` ("arm" or "grasp")."""
    module, name = getattr(settings, rig).split(":")
    return getattr(importlib.import_module(module), name)


class ContactRows:
    """The contact questions (``EngineAdapter.object_contacts``, ``touch``, ``contact_summary``)
    of an adapter that reads the step's object-robot contacts within the step as rows (body,
    point, normal from the robot towards the object, normal force) into its ``contacts``, its
    bodies' names and parts ("arm" where None) in its ``body_names`` and ``part_of_body``."""

    contacts: list
    body_names: Sequence[str]
    part_of_body: Sequence[str | None]

    def object_contacts(self, pos, v) -> list:
        return self.contacts

    def touch(self, contacts: list) -> tuple:
        c = max(contacts, key=lambda c: c[3])
        return c[0], c[1], c[2]

    def contact_summary(self) -> tuple[list, list, float]:
        """(parts, links, total normal force) of the step's contacts, sorted."""
        if not self.contacts:
            return [], [], 0.0
        bodies = {c[0] for c in self.contacts}
        links = sorted(self.body_names[b] for b in bodies)
        parts = sorted({self.part_of_body[b] or "arm" for b in bodies})
        return parts, links, float(sum(c[3] for c in self.contacts))


class EngineAdapter(Protocol):
    palm_id: int | None  # the engine's id of the palm link (None: no palm)

    def state(self) -> tuple:
        """((q, qd), hand (q, qd, effort), object (pos, orn xyzw, v, w) or None), read once
        after each step."""

    def invalidate_state(self) -> None:
        """Forget the state read (after setting the simulation other than by stepping it)."""

    def effector_now(self) -> tuple:
        """The tool frame's (pos, orn xyzw, v, w) now, read once a step."""

    def point_velocity(self, link: int, point) -> tuple[float, float, float]:
        """v + w x r of the point ``point`` moving with the robot link ``link`` (world)."""

    def object_contacts(self, pos, v) -> list:
        """The step's object-robot contact rows (the object at ``pos`` moving at ``v``)."""

    def touch(self, contacts: list) -> tuple:
        """(link, point, normal from the robot towards the object) of the strongest contact."""

    def contact_summary(self) -> tuple:
        """(parts, links, total normal force in N) of the step's contacts, sorted."""

    def set_object_velocity(self, v: list, w) -> None:
        """Set the object's velocity (a scenario's kick)."""

    def notes(self) -> dict:
        """The spec's notes on the engine."""

    def apply_torques(self, tau: list) -> None:
        """Apply the arm's torques (N*m, one per active joint) over the coming step."""

    def drive_hand(self, v: list, qd: list) -> None:
        """Drive the hand's servos at the speeds ``v`` (rad/s) over the coming step; ``qd``:
        the hand joints' speeds now."""

    def hold_object(self, obj: tuple) -> None:
        """Before the step: the forces the engine applies to the object itself (none, or
        gravity's cancelled where ``object_gravity`` is off and the engine needs a force)."""

    def advance(self) -> bool:
        """Step the engine by ``dt`` and forget the state read; True when the run has diverged
        (the engine says so)."""

    def inverse_dynamics(self, q, qd, qdd) -> tuple:
        """(tau, M): the engine's inverse dynamics and mass matrix of the active arm joints at
        (q, qd, qdd), one value per active joint, the hand's joints at rest at their posture now;
        the simulation's state unchanged (the cross-engine checks against our RNEA)."""

    def frames(self) -> list[Frame]:
        """Every URDF link in its parent link, the base in ``world``."""

    def close(self) -> None:
        """Free the engine's resources."""
