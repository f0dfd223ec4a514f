"""Packaging details pyproject.toml cannot say: the top-level data/, scenarios/ and sweeps/
folders ship in the wheel as package data under replay._shipped (found by replay.resources);
one hot path has an optional C accelerator, a ``_name.c`` beside the Python module it speeds
(plain C over the buffer protocol, no NumPy headers, a ``.pyi`` stub, a test holding it to the
Python path): ``ext_modules`` below (the cameras' raster). It is optional: where it does not
build (no C compiler, ``CC=/bin/false``, a compiler that rejects it) the install goes on without
it and the pure-Python path runs (replay.accel); docs/DESIGN.md, "Compiled code", says what it
gains. A wheel (or sdist) built from a git checkout records the checkout's commit in a generated
``replay/_build_info.py`` (replay.version reads it; a checkout reads git live)."""

from setuptools import Extension, find_namespace_packages, setup

import importlib.util
import os
import sys
from pathlib import Path

from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

# -fexcess-precision=standard and -ffp-contract=off: every double operation rounds once, as in
# Python and NumPy (no fused multiply-adds where a CPU has them: the kernels' tests compare with
# their Python references to the bit). GCC's options: other compilers get their own below.
GCC_FLAGS = ["-O2", "-fexcess-precision=standard", "-ffp-contract=off"]
CLANG_FLAGS = ["-O2", "-ffp-contract=off"]  # (clang has no excess precision on x86-64 SSE)
MSVC_FLAGS = ["/O2", "/fp:precise"]


class OptionalBuildExt(build_ext):
    """Each extension with its compiler's flags; one that fails to build is left out (its
    pure-Python path runs), said once on stderr."""

    def build_extension(self, ext):
        kind = self.compiler.compiler_type
        cc = " ".join(getattr(self.compiler, "compiler_so", None) or [os.environ.get("CC", "")])
        if kind == "msvc":
            ext.extra_compile_args = MSVC_FLAGS
        elif "clang" in cc:
            ext.extra_compile_args = CLANG_FLAGS
        else:
            ext.extra_compile_args = GCC_FLAGS
        try:
            super().build_extension(ext)
        except Exception as exc:  # (CompileError, LinkError, a missing compiler)
            print(
                f"paper-replay: optional accelerator {ext.name} not built ({exc}); "
                "its pure-Python path will run",
                file=sys.stderr,
            )


BUILD_INFO = "replay/_build_info.py"


def _write_build_info(root: str) -> None:
    """``root``/replay/_build_info.py with this checkout's commit; nothing outside a checkout
    (an sdist's own file is kept)."""
    here = Path(__file__).resolve().parent
    spec = importlib.util.spec_from_file_location("_replay_version", here / "replay/version.py")
    assert spec is not None and spec.loader is not None
    version = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(version)  # (the file alone: nothing of replay is imported)
    commit, diff = version.git_state(here)
    if not commit:
        return
    target = Path(root) / BUILD_INFO
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(
        '"""Written by setup.py when this package was built (replay.version reads it)."""\n\n'
        f"COMMIT = {commit!r}\nDIFF = {diff!r}  # digest of uncommitted changes, if any\n"
    )


class BuildPyWithCommit(build_py):
    """The build's ``replay/_build_info.py`` (never the checkout's: it reads git live)."""

    def run(self):
        super().run()
        if not getattr(self, "editable_mode", False):
            _write_build_info(self.build_lib)


class SdistWithCommit(sdist):
    def make_release_tree(self, base_dir, files):
        super().make_release_tree(base_dir, files)
        _write_build_info(base_dir)


def _ext(module: str) -> Extension:
    """The extension ``module`` built from the one C file of that dotted path."""
    return Extension(module, [module.replace(".", "/") + ".c"], optional=True)


SHIPPED = {
    "replay._shipped.data": "data",
    "replay._shipped.scenarios": "scenarios",
    "replay._shipped.sweeps": "sweeps",
}

setup(
    cmdclass={
        "build_ext": OptionalBuildExt,
        "build_py": BuildPyWithCommit,
        "sdist": SdistWithCommit,
    },
    packages=find_namespace_packages(include=["replay*", "plants*", "analysis*"]) + list(SHIPPED),
    package_dir=SHIPPED,
    ext_modules=[
        _ext("replay.sensors._pixels"),
    ],
    package_data={
        "replay._shipped.data": ["**/*"],
        "replay._shipped.scenarios": ["*.yaml"],
        "replay._shipped.sweeps": ["*.yaml"],
    },
)
