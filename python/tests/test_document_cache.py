"""DocumentCache and the document split, judged by the MuJoCo this venv has.

Every model the cache returns is compared with MuJoCo compiling the same XML: the judge's
whole-model comparison (every array, size, name and struct), then bit for bit on every
float array and statistic. Documents: the scenes' variants taken as documents, random
value edits of a seeded sample of the wheel corpus (robosuite robots, grippers, objects
and an arena among them), structural edits (which must compile), a caller changing the
model it was given, threads, errors.

Runs under 3.17.0 and again under 4.0.0 (scripts/test.sh): the package's MuJoCo calls are
the installed ``mujoco``'s, so what it checks depends on that version.
"""
from __future__ import annotations

import copy
import random
import threading

import mujoco
import numpy as np
import pytest

import judge
import mjcf_forge
from helpers import CORPUS, MODELS_TXT, ROOT, RS_ASSETS
from helpers import not_bit_identical
from mjcf_forge._mjcf_forge import PatchPlan

SCENES = [
    ROOT / "corpora" / "scenes" / "patch" / "patch.toml",
    ROOT / "corpora" / "scenes" / "patch" / "structural.toml",
    ROOT / "corpora" / "scenes" / "patch" / "aligned.toml",
    ROOT / "corpora" / "scenes" / "demo" / "demo.toml",
    ROOT / "benches" / "scenes" / "lift5_fixed.toml",
]

# The same sample as tests/document_cache.rs.
SAMPLE = [
    "robosuite-1.5.2/robosuite/models/assets/robots/panda/robot.xml",
    "robosuite-1.5.2/robosuite/models/assets/robots/sawyer/robot.xml",
    "robosuite-1.5.2/robosuite/models/assets/robots/ur5e/robot.xml",
    "robosuite-1.5.2/robosuite/models/assets/grippers/panda_gripper.xml",
    "robosuite-1.5.2/robosuite/models/assets/grippers/robotiq_gripper_140.xml",
    "robosuite-1.5.2/robosuite/models/assets/objects/can.xml",
    "robosuite-1.5.2/robosuite/models/assets/objects/milk.xml",
    "robosuite-1.5.2/robosuite/models/assets/arenas/table_arena.xml",
    "brax-0.14.2/brax/envs/assets/ant.xml",
    "brax-0.14.2/brax/envs/assets/reacher.xml",
    "brax-0.14.2/brax/test_data/fluid_box.xml",
    "dm_control-1.0.50/dm_control/mjcf/test_assets/robot_arm.xml",
    "dm_control-1.0.50/dm_control/suite/acrobot.xml",
    "dm_control-1.0.50/dm_control/suite/finger.xml",
    "dm_control-1.0.50/dm_control/suite/point_mass.xml",
    "dm_control-1.0.50/dm_control/third_party/kinova/jaco_arm.xml",
    "fancy_gym-0.3.0/fancy_gym/envs/mujoco/hopper_jump/assets/hopper_jump_on_box.xml",
    "gym_aloha-0.1.5/gym_aloha/assets/bimanual_viperx_end_effector_transfer_cube.xml",
    "gymnasium-1.4.0/gymnasium/envs/mujoco/assets/pusher.xml",
    "myo_sim-0.2.3/myo_sim/models/legacy/elbow/myoelbow_1dof6muscles_1dofSoftexo_sim2.xml",
]


def check_exact(doc, model, what="") -> None:
    ref = mujoco.MjModel.from_xml_string(doc.to_xml())
    diffs = judge.compare_models(ref, model)
    assert diffs == [], f"{what}: {diffs[:5]}"
    assert not_bit_identical(ref, model) == [], what


def sample_docs():
    if not MODELS_TXT.is_file():
        pytest.skip("setup not run")
    listed = set(MODELS_TXT.read_text().split())
    docs = []
    for path in SAMPLE:
        full = CORPUS / path
        if f".cache/corpus/{path}" in listed or full.is_file():
            docs.append((path, mjcf_forge.Document.load(full)))
    assert len(docs) == len(SAMPLE)
    return docs


def fmt(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def new_value(tag: str, attr: str, old: str, rng: random.Random) -> str | None:
    """A value in the range MuJoCo takes, with as many numbers as the old one (None for
    an attribute left alone)."""
    try:
        v = [float(x) for x in old.split()]
    except ValueError:
        return None
    n = len(v)

    def r(lo, hi, k):
        return [rng.uniform(lo, hi) for _ in range(k)]

    if attr == "rgba" and n == 4:
        return fmt(r(0, 1, 4))
    table = {
        ("geom", "friction", 3): lambda: r(0.1, 2, 3),
        ("geom", "solref", 2): lambda: [rng.uniform(0.005, 0.05), rng.uniform(0.5, 1.5)],
        ("geom", "solimp", 5): lambda: [rng.uniform(0.5, 0.9), rng.uniform(0.9, 0.99), 0.001, 0.5, 2],
        ("geom", "margin", 1): lambda: r(0, 0.01, 1),
        ("light", "diffuse", 3): lambda: r(0, 1, 3),
        ("light", "specular", 3): lambda: r(0, 1, 3),
        ("camera", "fovy", 1): lambda: r(30, 90, 1),
        ("body", "pos", 3): lambda: [x + rng.uniform(-0.05, 0.05) for x in v],
        ("position", "kp", 1): lambda: r(1, 500, 1),
        ("velocity", "kv", 1): lambda: r(1, 500, 1),
        ("option", "timestep", 1): lambda: r(0.001, 0.005, 1),
        ("option", "gravity", 3): lambda: [0, 0, rng.uniform(-12, -8)],
    }
    for a in ("damping", "armature", "frictionloss", "stiffness"):
        table[("joint", a, 1)] = lambda: r(0, 2, 1)
    for a in ("specular", "shininess", "reflectance", "emission"):
        table[("material", a, 1)] = lambda: r(0, 1, 1)
    if (tag, attr) == ("body", "quat") and n == 4:
        q = np.array(r(-1, 1, 4))
        return fmt(q / np.linalg.norm(q))
    make = table.get((tag, attr, n))
    return fmt(make()) if make else None


PRIMITIVES = {"sphere", "capsule", "ellipsoid", "cylinder", "box"}


def edit_values(doc, rng: random.Random) -> int:
    """Changes a random half of the document's patchable values; how many it changed."""
    changed = 0
    for el in doc.root.iter():
        if (el.tag == "geom" and el.get("type", "sphere") in PRIMITIVES and "fromto" not in el.attrib
                and "size" in el.attrib and rng.random() < 0.5):
            el.attrib["size"] = fmt([float(x) * rng.uniform(0.8, 1.25) for x in el.attrib["size"].split()])
            changed += 1
        if el.tag == "inertial":
            if rng.random() < 0.5 and "mass" in el.attrib and "diaginertia" in el.attrib:
                f = rng.uniform(0.5, 2)
                el.attrib["mass"] = fmt([float(el.attrib["mass"]) * f])
                el.attrib["diaginertia"] = fmt([float(x) * f for x in el.attrib["diaginertia"].split()])
                changed += 1
            continue
        for attr, old in el.items():
            if rng.random() < 0.5:
                value = new_value(el.tag, attr, old, rng)
                if value is not None:
                    el.attrib[attr] = value
                    changed += 1
    return changed


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.name)
def test_scene_variants_as_documents_are_exact(path):
    if "lift5" in path.name and not RS_ASSETS.is_dir():
        pytest.skip("setup not run")
    scene = mjcf_forge.Scene.load(path)
    cache = mjcf_forge.DocumentCache(max_models=16)
    keys = set()
    for i in range(6):
        doc = scene.variant(i).document
        keys.add(doc.structure_key)
        check_exact(doc, cache.model(doc), f"{path.name} variant {i}")
    assert cache.compiles == len(keys)
    assert cache.patches == 6 - len(keys)


def test_random_value_edits_of_wheel_models_are_exact():
    rng = random.Random(21)
    cache = mjcf_forge.DocumentCache(max_models=4)
    edits = hits = sized = 0
    for path, doc in sample_docs():
        check_exact(doc, cache.model(doc), path)
        key = doc.structure_key
        for round_ in range(3):
            edited = doc.copy()
            edits += edit_values(edited, rng)
            patches = cache.patches
            check_exact(edited, cache.model(edited), f"{path} round {round_}")
            if edited.structure_key == key:
                assert cache.patches == patches + 1, path
                hits += 1
                sized += any(f == "geoms" for _, _, f, _ in edited.patch)
    assert edits > 500, edits
    # Most edited documents are patched; the others compile (a muscle model patches only
    # visual values; poses of unnamed bodies and of models with keyframes are compiled;
    # sizes of world geoms, of geoms sized by fromto or in bodies with meshes, and sizes
    # under inertiafromgeom="true" are structure).
    assert hits >= 25, hits
    assert sized >= 10, sized  # with bodies whose geoms' sizes were patched


def test_sizes_of_primitive_geoms_are_patched_through_their_bodys_compile():
    xml = """<mujoco><compiler angle="degree"/><asset><material name="m" rgba="1 0 0 1"/></asset>
      <worldbody><geom name="floor" type="plane" size="1 1 0.1"/>
      <body name="cube" pos="0 0 0.1"><freejoint/>
        <geom name="c" type="box" size="{a}" material="m" euler="0 0 30"/>
        <geom name="c_vis" type="box" size="{a}" contype="0" conaffinity="0" group="1" mass="0"/>
        <site name="s" size="0.01"/></body>
      <body name="arm" pos="0.3 0 0.2"><joint name="j" axis="0 1 0"/>
        <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>
        <geom type="capsule" size="{r} 0.1"/><geom type="cylinder" size="{r} 0.05" pos="0 0 0.1"/>
        <body name="tip" pos="0 0 0.2"><joint axis="1 0 0"/><geom type="ellipsoid" size="{a}"/>
          <geom type="sphere" size="{r}" pos="0.05 0 0"/></body></body>
      <body name="pair" pos="0 0.3 0.1"><freejoint/><geom type="box" size="{b}"/>
        <geom type="box" size="{b}"/></body>
      </worldbody></mujoco>"""
    cache = mjcf_forge.DocumentCache()
    rng = random.Random(3)
    docs = []
    for k in range(8):
        a = fmt([rng.uniform(0.02, 0.04) for _ in range(3)])
        r = fmt([rng.uniform(0.01, 0.03)])
        b = fmt(sorted(rng.uniform(0.01, 0.03) for _ in range(3)))
        docs.append(mjcf_forge.Document.from_string(xml.format(a=a, r=r, b=b)))
    assert len({d.structure_key for d in docs}) == 1
    for k, doc in enumerate(docs):
        check_exact(doc, cache.model(doc), f"sizes {k}")
    assert (cache.compiles, cache.patches) == (1, 7)
    # Two boxes with their sizes in the other order turn the pair's principal axes: MuJoCo
    # then keeps its inertial frame apart from the body's (body_sameframe, body_simple),
    # which no patch changes: compiled, exact.
    uneven = mjcf_forge.Document.from_string(xml.format(a="0.03 0.03 0.03", r="0.02", b="0.03 0.02 0.01"))
    assert uneven.structure_key == docs[0].structure_key
    check_exact(uneven, cache.model(uneven), "uneven pair")
    assert cache.compiles == 2
    # The same structure again, patched, exact after the fallback.
    check_exact(docs[3], cache.model(docs[3]), "after the fallback")
    # World geoms, meshes and fromto stay structure.
    sizes = [(o, f) for o, _, f, _ in docs[0].patch if f == "geoms"]
    assert sizes == [("body", "geoms")] * 4


def test_files_meant_for_inclusion_are_answered_as_mujoco_compiles_them():
    # Bodies and frames directly under <mujoco> (a file meant to be included into a
    # <worldbody>): MuJoCo reads them and compiles the file to the world alone; the cache
    # answers the same, never refuses it: patches of the timestep, and other values in
    # what MuJoCo leaves out (in the structure key: compiled).
    cache = mjcf_forge.DocumentCache()
    for k, mass in enumerate(["1", "1", "1", "2.5"]):
        text = (
            f'<mujoco model="part"><option timestep="0.00{k + 1}"/>'
            f'<body name="b" pos="0 0 1"><geom name="g" size="0.1" mass="{mass}"/></body>'
            f'<frame pos="1 0 0"><body name="c"><joint name="j" damping="{mass}"/><geom size="0.2"/></body></frame>'
            "</mujoco>"
        )
        doc = mjcf_forge.Document.from_string(text)
        check_exact(doc, cache.model(doc), f"fragment {k}")
    assert (cache.compiles, cache.patches) == (2, 2)


def test_structural_edits_are_compiled_and_exact():
    cache = mjcf_forge.DocumentCache(max_models=64)
    for path, doc in sample_docs():
        cache.model(doc)
        edits = []
        added = doc.copy()
        added.worldbody.append("site", {"name": "doc_cache_site", "size": "0.01"})
        edits.append(("a site added", added))
        world_geoms = [g for g in doc.worldbody.findall("geom") if g.get("name") is None]
        if world_geoms:
            removed = doc.copy()
            removed.worldbody.remove(removed.worldbody.findall("geom")[
                doc.worldbody.findall("geom").index(world_geoms[0])])
            edits.append(("a geom removed", removed))
        geom = doc.find(".//geom")
        if geom is not None:
            changed = doc.copy()
            g = changed.find(".//geom")
            g.attrib["contype"] = "1" if g.get("contype") == "0" else "0"
            edits.append(("a geom's contype", changed))
            if geom.get("rgba") is None:
                coloured = doc.copy()
                coloured.find(".//geom").attrib["rgba"] = "0.25 0.5 0.75 1"
                edits.append(("an rgba added", coloured))
        for what, edited in edits:
            compiles = cache.compiles
            assert edited.structure_key != doc.structure_key, (path, what)
            check_exact(edited, cache.model(edited), f"{path}: {what}")
            assert cache.compiles == compiles + 1, (path, what)


def robot_doc():
    if not RS_ASSETS.is_dir():
        pytest.skip("setup not run")
    return mjcf_forge.Document.load(RS_ASSETS / "robots" / "panda" / "robot.xml")


def test_a_model_changed_by_its_caller_does_not_change_the_next():
    doc = robot_doc()
    cache = mjcf_forge.DocumentCache()
    other = doc.copy()
    other.find(".//joint").attrib["damping"] = "0.25"
    assert other.structure_key == doc.structure_key
    model = cache.model(doc)
    # What robosuite's modders do, in place: colours, frictions, masses, poses, damping,
    # option values, lights, cameras, the headlight; values no patch writes among them.
    model.geom_rgba[:] = 0.5
    model.geom_friction[:, 0] *= 3
    model.geom_size[:] *= 2
    model.body_mass[1:] *= 1.5
    model.body_pos[1:] += 0.01
    model.dof_damping[:] = 7
    model.actuator_gainprm[:, 0] += 1
    model.opt.timestep = 0.01
    model.opt.gravity[:] = [0, 0, -1]
    model.vis.headlight.ambient[:] = 0.9
    model.vis.map.znear = 0.5
    model.light_diffuse[:] = 0.1
    model.cam_fovy[:] = 10
    # Let go of (as robosuite drops its last simulation): the cache may patch it again.
    given = id(model)
    del model
    for d in (other, doc):
        got = cache.model(d)
        assert id(got) == given
        check_exact(d, got, "after the caller's changes")
        del got
    assert cache.compiles == 1


def test_a_model_someone_holds_is_never_patched_again():
    doc = robot_doc()
    cache = mjcf_forge.DocumentCache()
    docs = []
    for k in range(7):
        d = doc.copy()
        d.find(".//joint").attrib["damping"] = repr(0.1 * (k + 1))
        docs.append(d)
    first = cache.model(docs[0])
    data = mujoco.MjData(first)  # a simulation on it, as robosuite's MjSim
    del first
    held = [data, cache.model(docs[1]), cache.model(docs[2]).body_mass]  # a model, an array
    before = [copy.copy(data.model), copy.copy(held[1])]
    for k in range(3, 7):
        got = cache.model(docs[k])
        check_exact(docs[k], got, f"doc {k}")
        assert got is not data.model and got is not held[1]
        del got
    # What each holder has is what it was given.
    for kept, ref, d in zip((data.model, held[1]), before, docs):
        assert judge.compare_models(ref, kept) == []
    assert held[2].tolist() == mujoco.MjModel.from_xml_string(docs[2].to_xml()).body_mass.tolist()
    assert cache.compiles == 1 and cache.patches == 6
    # The structure keeps a few models per thread: holders beyond that keep theirs alone.
    assert cache._pool_len(docs[0]) <= 4
    # Once let go of, a model is patched again rather than copied.
    del held, data
    ids = {id(cache.model(docs[k])) for k in range(7)}
    assert len(ids) == 1 and cache._pool_len(docs[0]) <= 4


def test_a_held_model_given_back_is_patched_in_place():
    """``into=``: a held model of the document's structure is patched itself (what a
    robosuite hard reset that keeps its simulation asks); any other is left alone and
    the call is as without it."""
    doc = robot_doc()
    cache = mjcf_forge.DocumentCache()
    other = doc.copy()
    other.find(".//joint").attrib["damping"] = "0.25"
    held = cache.model(doc)
    data = mujoco.MjData(held)  # a simulation on it: held, so never patched without into=
    held.geom_rgba[:] = 0.5  # the caller's change, written back before the patch
    assert cache.model(other, into=held) is held
    check_exact(other, held, "patched in place")
    assert cache.model(doc, into=held) is held
    check_exact(doc, held, "patched in place again")
    # Another structure: a model of its own, the held one untouched.
    changed = doc.copy()
    changed.find(".//joint").attrib["type"] = "slide"
    before = copy.copy(held)
    got = cache.model(changed, into=held)
    assert got is not held
    check_exact(changed, got, "another structure")
    assert judge.compare_models(before, held) == []
    # A model the cache never gave: as without into=.
    stranger = mujoco.MjModel.from_xml_string(doc.to_xml())
    assert cache.model(other, into=stranger) is not stranger
    assert cache.compiles == 2 and cache.patches == 3
    del data


def test_threads_compile_a_structure_once_and_each_get_their_own_model():
    doc = robot_doc()
    cache = mjcf_forge.DocumentCache()
    docs = []
    for k in range(6):
        d = doc.copy()
        d.find(".//joint").attrib["damping"] = repr(0.1 * (k + 1))
        docs.append(d)
    start = threading.Barrier(len(docs))
    got: dict[int, object] = {}
    errors = []

    def ask(k):
        try:
            start.wait()
            for _ in range(3):
                got[k] = cache.model(docs[k])
                check_exact(docs[k], got[k], f"thread {k}")
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=ask, args=(k,)) for k in range(len(docs))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert cache.compiles == 1
    assert len({id(m) for m in got.values()}) == len(docs)
    assert cache.patches == 3 * len(docs) - 1


def test_mujoco_errors_point_at_the_source_and_leave_the_cache_alone(tmp_path):
    cache = mjcf_forge.DocumentCache()
    good = ("<mujoco><worldbody><body name='b'><freejoint/>"
            "<geom name='g' size='.1' rgba='1 0 0 1'/></body></worldbody></mujoco>")
    cache.model(good)
    state = (len(cache), cache.compiles, cache.patches, cache.nbytes)
    bad = ("<mujoco>\n<worldbody>\n<body name='b'>\n<freejoint/>\n"
           "<geom name='g' type='mesh' mesh='missing'/>\n</body>\n</worldbody>\n</mujoco>")
    with pytest.raises(mjcf_forge.MjcfError) as err:
        cache.model(bad)
    assert str(err.value).startswith("<string>:5:1: "), str(err.value)
    assert "missing" in str(err.value) and err.value.errors == [str(err.value)]
    path = tmp_path / "bad.xml"
    path.write_text(bad)
    with pytest.raises(mjcf_forge.MjcfError) as err:
        cache.model(path)
    assert str(err.value).startswith(f"{path}:5:1: "), str(err.value)
    assert (len(cache), cache.compiles, cache.patches, cache.nbytes) == state
    # A material that does not exist, on a cached structure: MuJoCo's verdict too.
    mat = ("<mujoco><asset><material name='m'/></asset><worldbody>"
           "<geom name='g' size='.1' material='{}'/></worldbody></mujoco>")
    cache.model(mat.format("m"))
    with pytest.raises(mjcf_forge.MjcfError, match="nope"):
        cache.model(mat.format("nope"))
    doc = mjcf_forge.Document.from_string(mat.format("m"))
    check_exact(doc, cache.model(doc), "after an error")
    with pytest.raises(TypeError):
        cache.model(42)


def test_text_with_a_base_folder_and_paths():
    arm = ROOT / "corpora" / "scenes" / "demo" / "arm.xml"
    cache = mjcf_forge.DocumentCache()
    text = arm.read_text()
    from_text = cache.model(text, base_dir=arm.parent)
    check_exact(mjcf_forge.Document.load(arm), from_text, "text")
    given = id(from_text)
    del from_text  # let go of: the cache patches it again
    from_path = cache.model(arm)
    assert cache.compiles == 1 and cache.patches == 1
    assert id(from_path) == given


def test_the_cache_is_bounded_least_recently_used_out():
    xml = "<mujoco><worldbody><geom name='g' size='{}' rgba='1 0 0 1'/></worldbody></mujoco>"
    cache = mjcf_forge.DocumentCache(max_models=2)
    for size in ("0.1", "0.2", "0.3"):
        cache.model(xml.format(size))
    assert len(cache) == 2
    cache.model(xml.format("0.2"))
    assert cache.compiles == 3
    cache.model(xml.format("0.1"))
    assert cache.compiles == 4
    one = mjcf_forge.DocumentCache()
    one.model(xml.format("0.1"))
    small = mjcf_forge.DocumentCache(max_bytes=one.nbytes + 1)
    for size in ("0.1", "0.2", "0.3"):
        small.model(xml.format(size))
    assert len(small) == 1 and small.nbytes <= one.nbytes + 1
    with pytest.raises(ValueError):
        mjcf_forge.DocumentCache(max_models=0)


def test_structure_key_and_patch_read_the_document():
    xml = ("<mujoco><option timestep='{}'/><worldbody><body name='b' pos='0 0 {}'>"
           "<freejoint name='f'/><geom size='.1' rgba='1 0 0 1' mass='{}'/></body></worldbody>"
           "<actuator><general name='a' joint='f' gainprm='2'/></actuator></mujoco>")
    a = mjcf_forge.Document.from_string(xml.format("0.002", "1", "1"))
    b = mjcf_forge.Document.from_string(xml.format("0.004", "2", "1"))
    c = mjcf_forge.Document.from_string(xml.format("0.002", "1", "2"))
    assert a.structure_key == b.structure_key != c.structure_key
    assert len(a.structure_key) == 32
    patch = {(o, n, f): v for o, n, f, v in b.patch}
    assert patch[("option", 0, "timestep")] == (0.004,)
    assert patch[("body", "b", "pos")] == (0.0, 0.0, 2.0)
    assert patch[("joint", "f", "qpos0")] == (0.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0)
    assert patch[("geom", 0, "rgba")] == (1.0, 0.0, 0.0, 1.0)
    assert patch[("actuator", "a", "gainprm")] == (2.0,) + (0.0,) * 9
    # A default class added after loading is read as MuJoCo reads it.
    d = a.copy()
    default = d.root.makeelement("default", {})
    default.append("geom", {"friction": "0.5 0.1 0.01"})
    d.root.insert(0, default)
    assert d.structure_key != a.structure_key
    cache = mjcf_forge.DocumentCache()
    for doc in (a, b, d):
        check_exact(doc, cache.model(doc), "split")
    assert copy.copy(cache.model(a)).nbody == 2
