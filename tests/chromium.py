"""Debian's Chromium for the browser tests (shared/BROWSER-TESTS.md): its path, the flags that
work headless as root without a GPU, and an install through apt-get when it is missing."""

from __future__ import annotations

import ctypes.util
import os
import shutil
import subprocess
from pathlib import Path

import pytest

CHROMIUM = "/usr/bin/chromium"
_COMMON = [
    "--headless=new",
    "--no-sandbox",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
    "--disable-sync",
]
# WebGL without a GPU. Mesa's llvmpipe (through ANGLE's EGL back end) draws the viewer's first
# frame in ~2.5 s and ~3.5 s of the GPU process's CPU where SwiftShader takes ~6 s and ~8 s (the
# client's environment map is prefiltered on the first frame: 14 viewer pages a suite, each
# competing with the other test worker for the 2 cores); the pictures are the same. SwiftShader
# (shared/BROWSER-TESTS.md's flags) where Mesa's EGL is not installed.
LLVMPIPE = ["--use-gl=angle", "--use-angle=gl-egl", "--ignore-gpu-blocklist"]
SWIFTSHADER = ["--disable-gpu", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]


FLAGS = _COMMON + (LLVMPIPE if ctypes.util.find_library("EGL_mesa") else SWIFTSHADER)


def _ensure_chromium() -> str:
    if Path(CHROMIUM).is_file():
        return CHROMIUM
    if os.geteuid() != 0 or shutil.which("apt-get") is None:
        pytest.skip("no /usr/bin/chromium and no root apt-get to install it")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    for cmd in (["apt-get", "update", "-qq"], ["apt-get", "install", "-y", "-qq", "chromium"]):
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
        if r.returncode != 0:
            pytest.skip(f"could not install chromium: {r.stderr.strip()[-300:]}")
    return CHROMIUM
