"""Small URDF writer: links with inertial/visual/collision primitives, joints, deterministic files.

Plain URDF 1.0 with primitive geometry only (box, cylinder, sphere): loadable by PyBullet and by
viser's URDF loader (yourdfpy). Numbers are written with ``repr`` (shortest round-trip form), so
the same table gives byte-identical text.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from replay.robot.serial_chain import RigidBody
from replay.spatial import matrix_to_rpy


def fmt(x: float) -> str:
    x = float(x)
    if x == 0.0:
        return "0"
    return repr(x)


def fmt3(v) -> str:
    return " ".join(fmt(x) for x in v)


@dataclass
class Geometry:
    kind: str  # box | cylinder | sphere
    size: tuple  # box (x, y, z); cylinder (radius, length); sphere (radius,)
    origin: np.ndarray  # 4x4 in the link frame
    rgba: tuple = (0.7, 0.7, 0.7, 1.0)
    material: str = "grey"

    def xml(self, tag: str) -> str:
        rpy = matrix_to_rpy(self.origin[:3, :3])
        if self.kind == "box":
            g = f'<box size="{fmt3(self.size)}"/>'
        elif self.kind == "cylinder":
            g = f'<cylinder radius="{fmt(self.size[0])}" length="{fmt(self.size[1])}"/>'
        elif self.kind == "sphere":
            g = f'<sphere radius="{fmt(self.size[0])}"/>'
        else:
            raise ValueError(self.kind)
        mat = ""
        if tag == "visual":
            mat = (
                f'\n      <material name="{self.material}"><color rgba="{fmt3(self.rgba[:3])} '
                f'{fmt(self.rgba[3])}"/></material>'
            )
        return (
            f'    <{tag}>\n      <origin xyz="{fmt3(self.origin[:3, 3])}" rpy="{fmt3(rpy)}"/>\n'
            f"      <geometry>{g}</geometry>{mat}\n    </{tag}>\n"
        )


@dataclass
class Link:
    name: str
    body: RigidBody | None = None  # in the link frame; None = zero mass
    geometry: list[Geometry] = field(default_factory=list)
    collide: bool = True

    def xml(self) -> str:
        out = [f'  <link name="{self.name}">\n']
        b = self.body or RigidBody(0.0)
        inertia = 0.5 * (b.inertia + b.inertia.T)
        out.append(
            f'    <inertial>\n      <origin xyz="{fmt3(b.com)}" rpy="0 0 0"/>\n'
            f'      <mass value="{fmt(b.mass)}"/>\n'
            f'      <inertia ixx="{fmt(inertia[0, 0])}" ixy="{fmt(inertia[0, 1])}" '
            f'ixz="{fmt(inertia[0, 2])}" iyy="{fmt(inertia[1, 1])}" iyz="{fmt(inertia[1, 2])}" '
            f'izz="{fmt(inertia[2, 2])}"/>\n    </inertial>\n'
        )
        for g in self.geometry:
            out.append(g.xml("visual"))
            if self.collide:
                out.append(g.xml("collision"))
        out.append("  </link>\n")
        return "".join(out)


@dataclass
class Joint:
    name: str
    kind: str  # revolute | fixed
    parent: str
    child: str
    origin: np.ndarray  # 4x4, child frame at q = 0 in the parent frame
    axis: tuple = (0.0, 0.0, 1.0)
    lower: float = 0.0
    upper: float = 0.0
    effort: float = 0.0
    velocity: float = 0.0

    def xml(self) -> str:
        rpy = matrix_to_rpy(self.origin[:3, :3])
        s = (
            f'  <joint name="{self.name}" type="{self.kind}">\n'
            f'    <parent link="{self.parent}"/>\n    <child link="{self.child}"/>\n'
            f'    <origin xyz="{fmt3(self.origin[:3, 3])}" rpy="{fmt3(rpy)}"/>\n'
        )
        if self.kind != "fixed":
            s += (
                f'    <axis xyz="{fmt3(self.axis)}"/>\n'
                f'    <limit lower="{fmt(self.lower)}" upper="{fmt(self.upper)}" '
                f'effort="{fmt(self.effort)}" velocity="{fmt(self.velocity)}"/>\n'
                f'    <dynamics damping="0" friction="0"/>\n'
            )
        return s + "  </joint>\n"


def robot_xml(name: str, links: list[Link], joints: list[Joint], comment: str = "") -> str:
    head = '<?xml version="1.0"?>\n'
    if comment:
        head += "<!-- " + comment.replace("--", "-") + " -->\n"
    return (
        head
        + f'<robot name="{name}">\n'
        + "".join(l.xml() for l in links)
        + "".join(j.xml() for j in joints)
        + "</robot>\n"
    )


def cache_dir() -> Path:
    """Where generated model files go: $PAPER_REPLAY_CACHE, else a per-user temp folder."""
    env = os.environ.get("PAPER_REPLAY_CACHE")
    base = Path(env) if env else Path(tempfile.gettempdir()) / f"paper-replay-{os.getuid()}"
    return base / "models"


def write_cached(text: str, stem: str, directory: Path | None = None) -> Path:
    """Write ``text`` to ``<dir>/<stem>-<sha256[:16]>.urdf`` (atomically, once) and return the
    path: the same text always lands at the same path."""
    d = Path(directory) if directory is not None else cache_dir()
    d.mkdir(parents=True, exist_ok=True)
    path = d / f"{stem}-{hashlib.sha256(text.encode()).hexdigest()[:16]}.urdf"
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        fd, tmp = tempfile.mkstemp(dir=d, suffix=".tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    return path


def segment_cylinder(p0, p1, radius: float, **kw) -> Geometry | None:
    """A cylinder from point p0 to p1 (link frame), or None when they coincide."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    v = p1 - p0
    length = float(np.linalg.norm(v))
    if length < 1e-9:
        return None
    z = v / length
    # a rotation taking +z to z
    x = np.cross([0.0, 1.0, 0.0], z) if abs(z[1]) < 0.9 else np.cross(z, [1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, y, z])
    T[:3, 3] = (p0 + p1) / 2.0
    return Geometry("cylinder", (radius, length), T, **kw)
