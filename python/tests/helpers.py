"""Helpers the Python package's tests share: the checkout's paths, the wheel corpus,
robosuite's unpacked wheel as an importable package, and exact model comparison. Tests
import them (``from helpers import ROOT``); ``conftest.py`` holds pytest's hooks and
fixtures only.
"""
from __future__ import annotations

import importlib.machinery
import importlib.util
import sys
import types
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT / ".cache" / "corpus"
MODELS_TXT = CORPUS / "models.txt"
RS_ASSETS = CORPUS / "robosuite-1.5.2" / "robosuite" / "models" / "assets"


def corpus_models() -> list[Path]:
    """The wheel models MuJoCo compiles on their own (made by scripts/setup.sh)."""
    if not MODELS_TXT.is_file():
        pytest.fail(f"{MODELS_TXT} missing: run scripts/setup.sh")
    return [ROOT / line for line in MODELS_TXT.read_text().split()]


ROBOSUITE_PKG = ROOT / ".cache" / "corpus" / "robosuite-1.5.2" / "robosuite"


def stub_robosuite() -> None:
    """Makes robosuite 1.5.2's unpacked wheel importable as the package `robosuite` without
    running its __init__.py (which imports every environment), as
    benches/compare/bench_robosuite.py does; stand-ins for PIL and termcolor when they are not
    installed (the model classes never call them)."""
    if not ROBOSUITE_PKG.is_dir():
        pytest.fail(f"{ROBOSUITE_PKG} missing: run scripts/setup.sh")
    for name in ("PIL", "termcolor"):
        try:
            __import__(name)
        except ImportError:
            stand_in = types.ModuleType(name)
            stand_in.Image = None
            stand_in.colored = lambda text, *args, **kwargs: text
            sys.modules[name] = stand_in
    spec = importlib.machinery.ModuleSpec("robosuite", None, is_package=True)
    spec.submodule_search_locations = [str(ROBOSUITE_PKG)]
    pkg = importlib.util.module_from_spec(spec)
    pkg.__file__ = str(ROBOSUITE_PKG / "__init__.py")
    sys.modules["robosuite"] = pkg


def not_bit_identical(a, b) -> list[str]:
    """Float arrays and statistics of b that are not exactly those of a."""
    out = []
    for name in dir(a):
        x = getattr(a, name, None)
        if isinstance(x, np.ndarray) and x.dtype.kind == "f":
            if not np.array_equal(x, getattr(b, name), equal_nan=True):
                out.append(name)
    for s in ("meaninertia", "meanmass", "meansize", "extent"):
        if getattr(a.stat, s) != getattr(b.stat, s):
            out.append(f"stat.{s}")
    if not np.array_equal(a.stat.center, b.stat.center):
        out.append("stat.center")
    return out
