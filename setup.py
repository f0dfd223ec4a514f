"""Packaging details pyproject.toml cannot say: the top-level data/, scenarios/ and sweeps/
folders ship in the wheel as package data under replay._shipped (found by replay.resources);
the cameras' per-pixel kernels are a small C extension (replay/sensors/_pixels.c: plain C over
the buffer protocol, no NumPy headers), as are the stereo camera's frame and a sphere's silhouette
(replay/sensors/_stereo.c, _silhouette.c), the catching mapping
(replay/control/catching/_mapping.c), the serial chain's one-configuration dynamics
(replay/robot/_chain.c), the stick planners' sweep checks (replay/control/stick/_sweep.c), the
air table's once-a-step body input/output (plants/airtable/_bodies.c), the camera PNG encoder
(replay/foxglove/_png.c), the log's chunk buffer and finiteness check (replay/log/_chunk.c,
_finite.c) and the grasping tasks' per-step kernels (replay/control/grasping/_arm_kinematics.c,
_chip_target.c, _hand_servo.c)."""

from setuptools import Extension, find_namespace_packages, setup

SHIPPED = {
    "replay._shipped.data": "data",
    "replay._shipped.scenarios": "scenarios",
    "replay._shipped.sweeps": "sweeps",
}

setup(
    packages=find_namespace_packages(include=["replay*", "plants*", "analysis*"]) + list(SHIPPED),
    package_dir=SHIPPED,
    ext_modules=[
        Extension(
            "replay.sensors._pixels",
            ["replay/sensors/_pixels.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.sensors._stereo",
            ["replay/sensors/_stereo.c"],
            # included: _pixels.c's kernels, unchanged, and _silhouette.c's sphere outline
            depends=["replay/sensors/_pixels.c", "replay/sensors/_silhouette.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.sensors._silhouette",
            ["replay/sensors/_silhouette.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.control.catching._mapping",
            ["replay/control/catching/_mapping.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.robot._chain",
            ["replay/robot/_chain.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "plants.airtable._bodies",
            ["plants/airtable/_bodies.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.control.stick._sweep",
            ["replay/control/stick/_sweep.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.foxglove._png",
            ["replay/foxglove/_png.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.log._chunk",
            ["replay/log/_chunk.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.log._finite",
            ["replay/log/_finite.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.control.grasping._arm_kinematics",
            ["replay/control/grasping/_arm_kinematics.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.control.grasping._chip_target",
            ["replay/control/grasping/_chip_target.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
        Extension(
            "replay.control.grasping._hand_servo",
            ["replay/control/grasping/_hand_servo.c"],
            extra_compile_args=["-O2", "-fexcess-precision=standard"],
        ),
    ],
    package_data={
        "replay._shipped.data": ["**/*"],
        "replay._shipped.scenarios": ["*.yaml"],
        "replay._shipped.sweeps": ["*.yaml"],
    },
)
