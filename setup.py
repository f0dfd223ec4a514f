"""Packaging details pyproject.toml cannot say: the top-level data/, scenarios/ and sweeps/
folders ship in the wheel as package data under replay._shipped (found by replay.resources);
the hot paths are small C extensions, one ``_name.c`` beside the Python module it speeds (plain C
over the buffer protocol, no NumPy headers, each with a ``.pyi`` stub and a test holding it to its
Python reference): the list is ``ext_modules`` below."""

from setuptools import Extension, find_namespace_packages, setup

# -fexcess-precision=standard and -ffp-contract=off: every double operation rounds once, as in
# Python and NumPy (no fused multiply-adds where a CPU has them: the kernels' tests compare with
# their Python references to the bit)
FLAGS = ["-O2", "-fexcess-precision=standard", "-ffp-contract=off"]


# headers every module may include (replay/ is on the include path): floats between Python
# sequences and C arrays
SHARED = ["replay/_pyfloats.h"]


def _ext(module: str, depends: tuple[str, ...] = ()) -> Extension:
    """The extension ``module`` built from the one C file of that dotted path."""
    return Extension(
        module,
        [module.replace(".", "/") + ".c"],
        depends=[*depends, *SHARED],
        include_dirs=["replay"],
        extra_compile_args=FLAGS,
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
        # includes _pixels.c's kernels, unchanged
        _ext(
            "replay.sensors._stick_frame",
            ("replay/sensors/_pixels.c", "replay/sensors/_ellipse.h"),
        ),
        _ext("replay.control.stick._sweep"),
        _ext("replay.control.catching._mapping"),
        _ext("replay.control.catching._ballistic"),
        _ext("replay.control.catching._torque"),
        _ext("replay.control.grasping._arm_kinematics"),
        _ext("replay.control.grasping._chip_target"),
        _ext("replay.control.grasping._hand_servo"),
        _ext("plants.bullet_arm._arm_state"),
    ],
    package_data={
        "replay._shipped.data": ["**/*"],
        "replay._shipped.scenarios": ["*.yaml"],
        "replay._shipped.sweeps": ["*.yaml"],
    },
)
