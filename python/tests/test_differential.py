"""The Python DocumentCache against MuJoCo on random documents (the extension's
``_testing.random_mjcf``, the same generator as tests/document_differential.rs): every answer equals
MuJoCo compiling the same text, bit for bit, or both refuse it; and the caller's ways of
holding what it gets: models kept while later ones are patched, models the caller changes,
models given back with ``into``, threads sharing one cache. Fixed seeds (a short run in CI);
the long campaigns are scripts/differential.sh's, with their results in docs/limits.md."""
from __future__ import annotations

import os
import threading

import mujoco
import numpy as np

import judge
import mjcf_forge
from helpers import MASS_DERIVED, beyond, not_bit_identical, superset_check
from mjcf_forge._mjcf_forge import _testing
from mjcf_forge.batch import WorldBatch

# MJCF_FORGE_DIFFERENTIAL=SEEDS,VARIANTS for a longer run (scripts/differential.sh).
SEEDS, VARIANTS = (int(x) for x in os.environ.get("MJCF_FORGE_DIFFERENTIAL", "40,6").split(","))


def verdict(text: str, answer, path=None, masses: bool = False) -> str | None:
    """``None`` when ``answer`` (a model, or the exception the cache raised) is MuJoCo's own
    verdict on ``text`` (or on the file ``path``); else what differs. ``masses``: a scene's
    variant, whose geoms' densities may go through unit models: what follows from a body's
    mass properties (helpers' MASS_DERIVED) within 1e-12 relative, the rest bit for bit."""
    try:
        ref = mujoco.MjModel.from_xml_path(str(path)) if path else mujoco.MjModel.from_xml_string(text)
    except ValueError as e:
        return None if isinstance(answer, Exception) else f"MuJoCo refuses it ({e}), the cache answers"
    if isinstance(answer, Exception):
        return f"MuJoCo compiles it, the cache refuses: {answer}"
    inexact = not_bit_identical(ref, answer)
    if masses:
        inexact = [d for d in inexact if d not in MASS_DERIVED] + beyond(ref, answer, 1e-12)
    diffs = judge.compare_models(ref, answer) + inexact
    return f"{diffs[:4]}" if diffs else None


def ask(cache, text: str, **kw):
    try:
        return cache.model(mjcf_forge.Document.from_string(text), **kw)
    except (mjcf_forge.MjcfError, ValueError) as e:
        return e


def snapshot(model) -> bytes:
    """Every float array of ``model``, to tell later whether anything changed it."""
    return b"".join(
        getattr(model, n).tobytes()
        for n in dir(model)
        if isinstance(getattr(model, n, None), np.ndarray) and getattr(model, n).dtype.kind == "f"
    )


def test_random_documents_are_answered_as_mujoco_compiles_them():
    cache = mjcf_forge.DocumentCache()
    findings, held = [], []
    answered = refused = 0
    for seed in range(SEEDS):
        for variant in range(VARIANTS):
            text = _testing.random_mjcf(seed, variant)
            answer = ask(cache, text)
            problem = verdict(text, answer)
            if problem:
                findings.append(f"{seed}/{variant}: {problem}")
            elif isinstance(answer, Exception):
                refused += 1
            else:
                answered += 1
                # Held by the caller: no later patch may change it.
                if variant % 3 == 0:
                    held.append((seed, variant, answer, snapshot(answer)))
    assert findings == [], "\n".join(findings)
    for seed, variant, model, before in held:
        assert snapshot(model) == before, f"{seed}/{variant}: changed after it was returned"
    assert answered >= SEEDS * VARIANTS // 2, (answered, refused)
    assert cache.patches >= answered // 8, (cache.patches, answered)
    print(f"python: {answered} answered ({cache.compiles} compiles, {cache.patches} patches), "
          f"{refused} refused by both, {len(held)} held models unchanged")


def test_models_changed_or_given_back_by_the_caller_leave_later_answers_exact():
    cache = mjcf_forge.DocumentCache()
    findings = []
    for seed in range(100, 100 + SEEDS // 2):
        model = None
        for variant in range(VARIANTS):
            text = _testing.random_mjcf(seed, variant)
            # Every other call gives the last model back to be patched in place.
            answer = ask(cache, text, into=model) if model is not None and variant % 2 else ask(cache, text)
            problem = verdict(text, answer)
            if problem:
                findings.append(f"{seed}/{variant}: {problem}")
            if isinstance(answer, Exception):
                model = None
                continue
            # The caller scribbles over what it got: the next answer is exact all the same.
            answer.geom_rgba[:] = 0.5
            answer.body_mass[:] *= 2
            answer.opt.timestep = 0.123
            model = answer
    assert findings == [], "\n".join(findings)


def test_threads_sharing_one_cache_each_get_exact_answers():
    cache = mjcf_forge.DocumentCache()
    findings: list[str] = []

    def work(first: int) -> None:
        for seed in range(first, first + 6):
            for variant in range(VARIANTS):
                text = _testing.random_mjcf(seed, variant)
                problem = verdict(text, ask(cache, text))
                if problem:
                    findings.append(f"{seed}/{variant}: {problem}")

    # Two threads on the same seeds (the same structures at once), one on others.
    threads = [threading.Thread(target=work, args=(s,)) for s in (200, 200, 300)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert findings == [], "\n".join(findings)


def test_random_scenes_through_the_model_cache_and_the_superset(tmp_path):
    # Random scenes (the extension's _testing.random_scene): each variant patched by the plain
    # ModelCache equals MuJoCo compiling its XML, bit for bit (what follows from mass
    # properties combined through a unit model within 1e-12 relative); through the superset, every
    # named element has the variant's values, the same contacts at the initial pose, parked
    # objects stay put and placed ones follow the variant's own trajectory (helpers'
    # superset_check; within 1 cm over 100 steps: random objects rest on cylinder rims and
    # box edges, where the superset's larger constraint problem (the parked objects' dofs)
    # rounds otherwise and contacts amplify it; 1.1 mm seen; parked objects within 1e-12 m
    # over 1,000 steps: gravity compensation holds them up to rounding, 1.2e-17 m seen); a
    # scene the superset cannot hold is refused with an error, never answered wrongly.
    findings, answered, refused, supersets = [], 0, 0, 0
    for seed in range(SEEDS // 2):
        toml, files = _testing.random_scene(seed)
        folder = tmp_path / str(seed)
        folder.mkdir()
        for name, text in files:
            (folder / name).write_text(text)
        (folder / "scene.toml").write_text(toml)
        try:
            scene = mjcf_forge.Scene.load(folder / "scene.toml")
        except mjcf_forge.MjcfError:
            refused += 1
            continue
        cache = mjcf_forge.ModelCache(scene)
        for i in range(VARIANTS + 4):
            v = scene.variant(i)
            problem = verdict(v.xml, cache.model(v), masses=True)
            if problem:
                findings.append(f"scene {seed}, variant {i}: {problem}")
            answered += 1
        try:
            sup = superset_check(
                scene, range(3), trajectory_tolerance=1e-2, parked_tolerance=1e-12, mass_tolerance=1e-12
            )
        except mjcf_forge.MjcfError:
            continue  # structure a superset cannot carry: refused, said so
        supersets += 1
        # WorldBatch: each world's rows are its variant's superset model (judged above); a
        # world the superset cannot carry (a body model of another layout) is refused.
        try:
            batch = WorldBatch(sup, range(4))
        except mjcf_forge.MjcfError:
            continue
        for w in range(4):
            model = sup.model(scene.variant(w))
            for field in batch.per_world:
                want = getattr(model.stat, field[5:]) if field.startswith("stat.") else getattr(model, field)
                if not np.array_equal(batch.arrays[field][w], want):
                    findings.append(f"scene {seed}, world {w}: {field}")
    assert findings == [], "\n".join(findings)
    assert answered >= SEEDS, (answered, refused)
    assert supersets >= SEEDS // 8, supersets
    print(f"scenes: {answered} variants answered, {supersets} supersets judged, {refused} scenes refused when loading")


def test_random_documents_with_includes_are_answered_as_mujoco_compiles_them(tmp_path):
    # A model whose first body is in a file its <worldbody> includes: loaded from the file,
    # answered as MuJoCo compiles the file.
    cache = mjcf_forge.DocumentCache()
    findings, included = [], 0
    for seed in range(SEEDS * 2):
        if len(_testing.random_mjcf_files(seed, 0)) < 2:
            continue
        folder = tmp_path / str(seed)
        folder.mkdir()
        for variant in range(VARIANTS):
            for name, text in _testing.random_mjcf_files(seed, variant):
                (folder / name).write_text(text)
            path = folder / "model.xml"
            try:
                answer = cache.model(mjcf_forge.Document.load(path))
            except (mjcf_forge.MjcfError, ValueError) as e:
                answer = e
            problem = verdict(None, answer, path)
            if problem:
                findings.append(f"{seed}/{variant}: {problem}")
            included += 1
    assert findings == [], "\n".join(findings)
    assert included >= SEEDS, included
