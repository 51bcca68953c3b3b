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

from mjcf_forge._mjcf_forge import MASS_DERIVED as _MASS_DERIVED

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


# What follows from a body's mass properties, where a unit model's patch may differ from the
# compile in the last bits (mjcf_forge::split::MASS_DERIVED, through the extension).
MASS_DERIVED = set(_MASS_DERIVED)


def beyond(a, b, bound: float) -> list[str]:
    """Float arrays and statistics of b that differ from a's by more than ``bound``,
    relative to the larger of the two values (or to the array's largest magnitude, for
    values near zero), as CompiledModel::differences_beyond judges in Rust."""
    out = []
    for name in dir(a):
        x = getattr(a, name, None)
        if isinstance(x, np.ndarray) and x.dtype.kind == "f":
            y = getattr(b, name)
            if x.dtype == np.float32:
                if not np.array_equal(x, y, equal_nan=True):
                    out.append(name)
                continue
            d = np.abs(x - y)
            scale = np.max(np.abs(x)) if x.size else 0.0
            bad = (d > bound * np.maximum(np.abs(x), np.abs(y))) & (d > bound * scale)
            if bad.any():
                out.append(name)
    for s in ("meaninertia", "meanmass", "meansize", "extent"):
        x, y = getattr(a.stat, s), getattr(b.stat, s)
        if abs(x - y) > bound * max(abs(x), abs(y)):
            out.append(f"stat.{s}")
    return out


def superset_check(scene, indices, trajectory_tolerance, parked_tolerance=0.0, mass_tolerance=0.0):
    """The superset judged on each variant: every named body, geom and joint of the
    variant's own compile has the same values in the patched superset (under its superset
    name; a body's inertia, principal axes and joints' ``M0`` within ``mass_tolerance``
    relative, where a unit model combines its geoms), the same contacts at the initial
    pose, parked objects never touch anything and stay put over 1,000 steps, and placed
    objects follow the variant's own trajectory over 100 steps."""
    import mujoco

    import mjcf_forge

    cache = mjcf_forge.ModelCache(scene, superset=True)
    sup = cache.superset
    for i in indices:
        v = scene.variant(i)
        ref = mujoco.MjModel.from_xml_string(v.xml)
        model = cache.model(v)
        tags = sup.names(i)

        def name(n):
            return next((t + n for p, t in tags if n.startswith(p)), n)

        checks = (
            (ref.nbody, ref.body, model.body, ("mass", "inertia", "pos", "quat", "ipos", "iquat", "subtreemass")),
            (ref.ngeom, ref.geom, model.geom, ("rgba", "friction", "size", "pos", "quat", "contype", "conaffinity", "solref", "solimp", "margin", "gap")),
            (ref.njnt, ref.joint, model.joint, ("qpos0", "qpos_spring", "range", "damping", "armature", "frictionloss", "M0")),
        )
        for count, ours, theirs, fields in checks:
            for k in range(count):
                n = ours(k).name
                # The world's subtree holds the parked objects too.
                if not n or n == "world":
                    continue
                for f in fields:
                    a, b = getattr(ours(k), f), getattr(theirs(name(n)), f)
                    if f in ("inertia", "iquat", "M0"):
                        scale = np.maximum(np.maximum(np.abs(a), np.abs(b)), 1e-300)
                        assert np.all(np.abs(a - b) <= mass_tolerance * scale), (i, n, f, a, b)
                    else:
                        assert np.array_equal(a, b), (i, n, f, a, b)
        d_ref, d = mujoco.MjData(ref), mujoco.MjData(model)
        mujoco.mj_forward(ref, d_ref)
        mujoco.mj_forward(model, d)

        def contacts(m, dd, rename):
            # By the geoms' names (an unnamed geom of the variant's, which the superset
            # names, by "?"), then where and how deep.
            def label(g):
                n = m.geom(g).name
                return "?" if not n or "unnamed_geom" in n else rename(n)

            return sorted(
                (tuple(sorted((label(c.geom[0]), label(c.geom[1])))), tuple(c.pos), c.dist)
                for c in dd.contact[: dd.ncon]
            )

        assert contacts(ref, d_ref, name) == contacts(model, d, lambda n: n)
        parked = [model.body(r).id for r in sup.parked(i)]
        start = d.xpos[parked].copy()
        for step in range(1000):
            if step < 100:
                mujoco.mj_step(ref, d_ref)
            mujoco.mj_step(model, d)
            if step == 99:
                for o in v.params["objects"]:
                    dev = np.abs(d_ref.body(o["body"]).xpos - d.body(name(o["body"])).xpos).max()
                    assert dev <= trajectory_tolerance, (i, o["body"], dev)
            parked_geoms = set(np.flatnonzero(np.isin(model.body_rootid[model.geom_bodyid], parked)))
            assert not any(c.geom[0] in parked_geoms or c.geom[1] in parked_geoms for c in d.contact[: d.ncon])
        assert np.abs(d.xpos[parked] - start).max(initial=0.0) <= parked_tolerance, (i, np.abs(d.xpos[parked] - start).max())
    return cache
