"""URDF builders from parameter tables (WAM arms, hands): primitive geometry, no meshes."""

from plants.models.arm import ArmModel, build_arm
from plants.models.urdf import cache_dir, write_cached

__all__ = ["ArmModel", "build_arm", "cache_dir", "write_cached"]
