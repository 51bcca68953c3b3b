"""WorldBatch on CPU MuJoCo, judged by MuJoCo: its per-world arrays are what
``mj_setConst`` gives (derived tree by tree or on the whole superset, the same bits), and
each world starts at its own keyframe rows. The batched simulators themselves (MuJoCo
Warp, MJX) judge it in ``test_batch_sim.py``.

Runs under 3.17.0 and again under 4.0.0 (scripts/test.sh): the package's MuJoCo calls are
the installed ``mujoco``'s, so what it checks depends on that version.
"""
from __future__ import annotations

import copy
from pathlib import Path

import mujoco
import numpy as np
import pytest

import mjcf_forge
from helpers import ROOT, RS_ASSETS, not_bit_identical
from mjcf_forge.batch import WorldBatch

PATCH = ROOT / "corpora" / "scenes" / "patch"
LIFT5 = ROOT / "benches" / "scenes" / "lift5.toml"


@pytest.mark.parametrize(
    "path, worlds, by_tree",
    [
        (PATCH / "mass.toml", 24, True),  # masses through body models (frames, meshes)
        (PATCH / "fixed.toml", 24, True),  # fixed bases (no dofs) beside free objects
        (PATCH / "boxes.toml", 24, True),
        (PATCH / "patch.toml", 8, False),  # the robot's armature: a tree with actuators
        (LIFT5, 64, True),
    ],
    ids=lambda p: p.stem if isinstance(p, Path) else str(p),
)
def test_worlds_derived_tree_by_tree_are_mj_setconsts(path, worlds, by_tree):
    # WorldBatch derives what mj_setConst would, per tree the patch writes into (each
    # compiled alone as a skeleton) and on the superset for what spans trees: every
    # per-world array and statistic must be the same bits as with mj_setConst itself.
    if path == LIFT5 and not RS_ASSETS.is_dir():
        pytest.skip("setup not run")
    scene = mjcf_forge.Scene.load(path)
    cache = mjcf_forge.ModelCache(scene, superset=True)
    fast = WorldBatch(cache, range(worlds))
    assert fast.derived_by_tree == (worlds if by_tree else 0)
    # The batch patches the cache's own model, and so may anyone (it notices): worlds
    # reassigned after another variant was patched in.
    cache.model(scene.variant(worlds + 100))
    fast.assign([2, 3, 4], [worlds + 101, worlds + 102, worlds + 103])
    assert fast.derived_by_tree == (worlds + 3 if by_tree else 0)
    # The cache's own models (a variant ready on CPU MuJoCo) derive tree by tree too, also
    # right after a patch made with mj_setConst (the trees' values then are that one's).
    by_tree_before = cache.by_tree
    ready = []
    for k in (200, 201, 202):
        cache.derive_by_tree = False
        cache.model(scene.variant(worlds + 300 + k))
        cache.derive_by_tree = True
        ready.append(copy.copy(cache.model(scene.variant(worlds + k))))
    assert cache.by_tree == by_tree_before + (3 if by_tree else 0)
    cache.derive_by_tree = False
    for k, model in zip((200, 201, 202), ready):
        assert not_bit_identical(cache.model(scene.variant(worlds + k)), model) == [], k
    whole = WorldBatch(cache, range(worlds))
    assert whole.derived_by_tree == 0
    whole.assign([2, 3, 4], [worlds + 101, worlds + 102, worlds + 103])
    assert fast.per_world == whole.per_world
    for name in whole.per_world:
        assert np.array_equal(fast.arrays[name], whole.arrays[name]), name
    assert np.array_equal(fast.parked_geoms, whole.parked_geoms)
    # Models for MuJoCo's batch API: each world's superset model (the chosen worlds' only:
    # all of lift5's 64 would take 7.9 GB), in the order asked.
    ours = fast.mujoco_models([2, 0])
    for w, model in zip((2, 0), ours):
        assert np.array_equal(model.body_invweight0, whole.arrays["body_invweight0"][w])
    if worlds <= 24:
        every = fast.mujoco_models()
        assert len(every) == worlds
        assert not_bit_identical(every[2], ours[0]) == [] and not_bit_identical(every[0], ours[1]) == []


def test_worlds_start_at_their_own_keyframe_rows():
    # A robot with keyframes, objects placed around it: each world's key rows are its own
    # patched model's (an object's rows are its pose there, placed or parked), which is the
    # variant's own compile; WorldBatch(key=...) starts each world there.
    scene = mjcf_forge.Scene.load(ROOT / "corpora" / "scenes" / "keyframe" / "keyframe.toml")
    cache = mjcf_forge.ModelCache(scene, superset=True)
    batch = WorldBatch(cache, [2, 0, 3, 1], key="robot0_home")
    assert batch.key == batch.model.key("robot0_home").id and batch.keys["key_qpos"].shape[:2] == (4, 2)
    start = batch.initial()
    for w, i in enumerate(batch.world_variant):
        v = scene.variant(int(i))
        model = cache.model(v)
        for name, rows in batch.keys.items():
            assert np.array_equal(rows[w], getattr(model, name)), (w, name)
        # The same state as MuJoCo's own reset to the key in the variant's own model, joint
        # by joint (the superset holds more joints: the parked candidates').
        ref = mujoco.MjModel.from_xml_string(v.xml)
        d = mujoco.MjData(ref)
        mujoco.mj_resetDataKeyframe(ref, d, ref.key("robot0_home").id)
        tags = cache.superset.names(int(i))
        for j in range(ref.njnt):
            n = ref.joint(j).name
            ours = model.joint(next((t + n for p, t in tags if n.startswith(p)), n))
            width = {0: 7, 1: 4}.get(int(ref.jnt_type[j]), 1)
            a, b = ref.jnt_qposadr[j], ours.qposadr[0]
            assert np.array_equal(start["qpos"][w, b : b + width], d.qpos[a : a + width]), (w, n)
        assert np.array_equal(start["ctrl"][w], d.ctrl)
    # Without a key: qpos0; a key by id; unknown keys refused before any array.
    assert np.array_equal(WorldBatch(cache, [2, 0]).qpos, batch.qpos0[:2])
    assert np.array_equal(WorldBatch(cache, [2], key=1).qpos[0], batch.keys["key_qpos"][0, 1])
    with pytest.raises(mjcf_forge.MjcfError, match="no keyframe 'away'.*robot0_home"):
        WorldBatch(cache, [0], key="away")
    with pytest.raises(mjcf_forge.MjcfError, match="keyframe 5 is out of range"):
        WorldBatch(cache, [0], key=5)
