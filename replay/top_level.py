"""The distribution's other top-level packages, ``plants`` and ``analysis``, are always the ones
installed beside ``replay``: a folder of the same name earlier on ``sys.path`` (the current
directory of ``python -m``, ``python -c``, a notebook, a Ray worker) does not shadow them.

:func:`guard` puts a finder for exactly these two names first on ``sys.meta_path``; it runs when
``replay.registry`` is imported (before any plug-in or analysis module loads) and in the
``replay`` executable. Only a package imported before ``replay`` is not covered.
docs/DESIGN.md, "Top-level packages", says why the folders stay top-level."""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import sys
from pathlib import Path

PACKAGES = ("plants", "analysis")
HOME = str(Path(__file__).resolve().parent.parent)  # site-packages, or the checkout


class _Beside(importlib.abc.MetaPathFinder):
    """Finds ``plants`` and ``analysis`` in :data:`HOME` only (their submodules follow their
    package's ``__path__``); anything else is left to the other finders."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in PACKAGES:
            return None
        return importlib.machinery.PathFinder.find_spec(fullname, [HOME])


def guard() -> None:
    if not any(isinstance(f, _Beside) for f in sys.meta_path):
        sys.meta_path.insert(0, _Beside())
