"""How far from its base any part of a fixed-base robot can be, in every configuration.

A link frame's origin is rigidly attached to its parent's link frame (URDF: the child frame is
the joint frame), so its distance from the parent's origin is the same in every configuration;
summed along the chain it bounds the origin's distance from the base. Every point of a link's
collision shapes (margin included) lies in the link's broadphase box, so the box's corner
farthest from the link's origin bounds the shapes about that origin in any orientation. The
largest of the sums is the robot's reach: nothing of it is farther from the base's link frame.
The plant uses it to skip asking for contacts while the free object is beyond it.
"""

from __future__ import annotations

import math


def _dist(a, b) -> float:
    return math.sqrt(sum((float(x) - float(y)) ** 2 for x, y in zip(a, b)))


def robot_reach(bc, robot: int, base_origin, parents: list[int]) -> float:
    """The reach (m) of ``robot`` (a fixed-base body of a BulletClient ``bc``) about
    ``base_origin`` (its base's link frame in the world), its links' parents by link index
    (-1: the base), read in the configuration it is in now."""
    origin = {-1: tuple(float(x) for x in base_origin)}
    chain = {-1: 0.0}  # bound on each link frame's distance from the base's
    lo, hi = bc.getAABB(robot, -1)
    reach = max(
        _dist(origin[-1], (x, y, z))
        for x in (lo[0], hi[0])
        for y in (lo[1], hi[1])
        for z in (lo[2], hi[2])
    )
    links = list(range(len(parents)))
    states = bc.getLinkStates(robot, links, computeForwardKinematics=1) if links else []
    for j, st in enumerate(states):  # parents come before their children (URDF order)
        origin[j] = tuple(st[4])
        chain[j] = chain[parents[j]] + _dist(origin[j], origin[parents[j]])
        lo, hi = bc.getAABB(robot, j)
        corners = [
            (x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])
        ]
        reach = max(reach, chain[j] + max(_dist(origin[j], c) for c in corners))
    return reach
