"""Packaging details pyproject.toml cannot say: the top-level data/, scenarios/ and sweeps/
folders ship in the wheel as package data under replay._shipped (found by replay.resources);
the cameras' per-pixel kernels are a small C extension (replay/sensors/_pixels.c: plain C over
the buffer protocol, no NumPy headers), as are the stereo camera's frame and a sphere's silhouette
(replay/sensors/_stereo.c, _silhouette.c), the catching mapping, ball estimator and torques
(replay/control/catching/_mapping.c, _ballistic.c, _torque.c), the serial chain's dynamics
(replay/robot/_chain.c), the stick planners' sweep checks (replay/control/stick/_sweep.c), the
air table's once-a-step body input/output (plants/airtable/_bodies.c), the camera PNG encoder
(replay/foxglove/_png.c), the log's chunk buffer and finiteness check (replay/log/_chunk.c,
_finite.c) and the grasping tasks' per-step kernels (replay/control/grasping/_arm_kinematics.c,
_chip_target.c, _hand_servo.c)."""

from setuptools import Extension, find_namespace_packages, setup

# -fexcess-precision=standard: every double operation rounds once, as in Python and NumPy (the
# kernels' tests compare with their Python references to the bit)
FLAGS = ["-O2", "-fexcess-precision=standard"]


def _ext(module: str, depends: tuple[str, ...] = ()) -> Extension:
    """The extension ``module`` built from the one C file of that dotted path."""
    return Extension(
        module, [module.replace(".", "/") + ".c"], depends=list(depends), extra_compile_args=FLAGS
    )


SHIPPED = {
    "replay._shipped.data": "data",
    "replay._shipped.scenarios": "scenarios",
    "replay._shipped.sweeps": "sweeps",
}

setup(
    packages=find_namespace_packages(include=["replay*", "plants*", "analysis*"]) + list(SHIPPED),
    package_dir=SHIPPED,
    ext_modules=[
        _ext("replay.sensors._pixels", ("replay/sensors/_ellipse.h",)),
        # includes _pixels.c's kernels, unchanged, and _silhouette.c's sphere outline
        _ext(
            "replay.sensors._stereo",
            (
                "replay/sensors/_pixels.c",
                "replay/sensors/_silhouette.c",
                "replay/sensors/_ellipse.h",
            ),
        ),
        _ext("replay.sensors._silhouette", ("replay/sensors/_ellipse.h",)),
        _ext("replay.control.catching._mapping"),
        _ext("replay.control.catching._ballistic"),
        _ext("replay.control.catching._torque"),
        _ext("replay.robot._chain"),
        _ext("plants.airtable._bodies"),
        _ext("replay.control.stick._sweep"),
        _ext("replay.foxglove._png"),
        _ext("replay.log._chunk"),
        _ext("replay.log._finite"),
        _ext("replay.control.grasping._arm_kinematics"),
        _ext("replay.control.grasping._chip_target"),
        _ext("replay.control.grasping._hand_servo"),
    ],
    package_data={
        "replay._shipped.data": ["**/*"],
        "replay._shipped.scenarios": ["*.yaml"],
        "replay._shipped.sweeps": ["*.yaml"],
    },
)
