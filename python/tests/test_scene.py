"""Scene and Variant: determinism across threads, windows and order; every variant
compiles in MuJoCo with its objects where ``params`` says; errors; bounded streaming."""
from __future__ import annotations

import json
import os
import sys
import time

import mujoco
import numpy as np
import pytest

from helpers import ROOT
from mjcf_forge import Document, MjcfError, Scene, Variant

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - the venv is 3.11; kept for 3.9/3.10 users running the tests
    import tomli as tomllib

DEMO_DIR = ROOT / "corpora" / "scenes" / "demo"
DEMO_TOML = DEMO_DIR / "demo.toml"


def rss_mib() -> float:
    """This process's resident memory now (not its peak, which earlier tests have set)."""
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


@pytest.fixture(scope="module")
def demo() -> Scene:
    return Scene.load()


def test_the_same_index_gives_the_same_bytes_whatever_the_threads_window_and_order(demo):
    one_by_one = [demo.variant(i).xml for i in range(40)]
    assert len(set(one_by_one)) == 40  # the variants really differ
    for threads in (1, 2, 4):
        for window in (None, 1, 7):
            got = [v.xml for v in demo.variants(range(40), threads=threads, window=window)]
            assert got == one_by_one, (threads, window)
    shuffled = [17, 3, 39, 0, 3]
    assert [(v.index, v.xml) for v in demo.variants(shuffled, threads=2)] == [
        (i, one_by_one[i]) for i in shuffled
    ]
    # A fresh scene (another load) gives the same bytes too.
    assert Scene.load().variant(11).xml == one_by_one[11]


def test_every_variant_compiles_with_its_objects_where_params_say(demo):
    template = mujoco.MjModel.from_xml_string(demo.template.to_xml())
    for v in demo.variants(range(25), threads=2):
        assert isinstance(v, Variant)
        m = v.compile()
        assert isinstance(m, mujoco.MjModel)
        objects = v.params["objects"]
        assert objects, v.index
        # Each placed object adds its bodies and exactly one free joint (7 qpos).
        assert m.njnt >= template.njnt + len(objects)
        for obj in objects:
            body = m.body(obj["body"])
            assert body.parentid[0] == 0  # placed in the world
            np.testing.assert_allclose(body.pos, obj["pos"], rtol=0, atol=1e-12)
            np.testing.assert_allclose(body.quat, obj["quat"], rtol=0, atol=1e-12)
        # Every randomized value is the one in the compiled model's source text.
        doc = v.document
        for r in v.params["randomized"]:
            if r.get("name"):
                el = doc.find_named(r["kind"], r["name"])
                assert el is not None, r


def test_variant_params_document_and_write(demo, tmp_path):
    v = demo.variant(5)
    assert v.index == 5 and "objects" in v.params and "randomized" in v.params
    assert v.params is not v.params  # a new dict each time: changing one changes nothing
    assert v.document.to_xml() == v.xml
    v.write(tmp_path / "v.xml")
    assert Document.load(tmp_path / "v.xml").to_xml() == v.xml
    assert mujoco.MjModel.from_xml_path(str(tmp_path / "v.xml")).nbody == v.compile().nbody
    assert repr(v).startswith("<mjcf_forge.Variant index=5")


def test_from_dict_is_the_scene_file_and_can_be_tweaked():
    description = tomllib.loads(DEMO_TOML.read_text())
    from_file = Scene.load(DEMO_TOML)
    from_dict = Scene.from_dict(description, DEMO_DIR)
    assert from_dict.seed == from_file.seed == 7
    assert [from_dict.variant(i).xml for i in range(5)] == [from_file.variant(i).xml for i in range(5)]
    description["seed"] = 8
    reseeded = Scene.from_dict(description, DEMO_DIR)
    assert reseeded.seed == 8 and reseeded.variant(0).xml != from_file.variant(0).xml
    # The TOML text itself, too.
    assert Scene.from_toml(DEMO_TOML.read_text(), DEMO_DIR).variant(3).xml == from_file.variant(3).xml
    # The file's models are absolute paths in the variant: it compiles from anywhere.
    assert all(p.is_absolute() for p in from_file.model_files)


def test_bad_scene_descriptions_raise_mjcf_error_with_positions():
    description = tomllib.loads(DEMO_TOML.read_text())
    description["colour"] = "red"
    with pytest.raises(MjcfError) as err:
        Scene.from_dict(description, DEMO_DIR)
    assert err.value.errors == [
        "<scene dict>: colour: unknown field `colour`, expected one of `seed`, `base`, "
        "`discard_visual`, `fixture`, `objects`, `randomize`"
    ]
    with pytest.raises(ValueError):  # not JSON data at all
        Scene.from_dict({"seed": {1, 2}}, DEMO_DIR)
    with pytest.raises(MjcfError) as err:
        Scene.load(DEMO_DIR / "missing.toml")
    assert "missing.toml" in err.value.errors[0]
    description = tomllib.loads(DEMO_TOML.read_text())
    description["base"] = "no_such_arena.xml"
    with pytest.raises(MjcfError) as err:
        Scene.from_dict(description, DEMO_DIR)
    assert "no_such_arena.xml" in str(err.value)


def test_a_variant_that_finds_no_place_names_group_and_index():
    description = tomllib.loads(DEMO_TOML.read_text())
    clutter = description["objects"][0]
    clutter["count"] = [30, 30]
    clutter["placement"].update(x=[0, 0.01], y=[0, 0.01], max_tries=2)
    scene = Scene.from_dict(description, DEMO_DIR)
    with pytest.raises(MjcfError) as err:
        scene.variant(4)
    assert "variant 4" in str(err.value) and "'clutter'" in str(err.value)
    stream = scene.variants(range(10), threads=2)
    with pytest.raises(MjcfError) as err:
        next(stream)
    assert "variant 0" in str(err.value)
    assert list(stream) == []  # a failed stream ends


def test_streaming_keeps_memory_bounded(demo):
    # A producer that ran ahead of its reader would make tens of thousands of variants in
    # the pause below (about 20 KB each as document + XML); the bounded window holds a few
    # dozen, whatever the reader does.
    stream = demo.variants(range(200_000), threads=2)
    next(stream)
    before = rss_mib()
    time.sleep(1.5)
    for _ in range(100):
        next(stream)
    grown = rss_mib() - before
    assert grown < 40, grown
    del stream  # the producer stops when its reader is gone


def test_bad_stream_arguments():
    scene = Scene.load()
    with pytest.raises(ValueError):
        scene.variants(range(3), threads=0)
    with pytest.raises(IndexError):
        scene.variants([-1])
    with pytest.raises(TypeError):
        scene.variants(5)


def test_scenes_and_variants_pickle(tmp_path, monkeypatch):
    import pickle

    description = tomllib.loads(DEMO_TOML.read_text())
    monkeypatch.chdir(DEMO_DIR)  # relative paths: the pickled copy must not depend on the folder
    scenes = [
        Scene.load(),
        Scene.load("demo.toml"),
        Scene.from_toml(DEMO_TOML.read_text()),
        Scene.from_dict(description),
    ]
    expected = [s.variant(9).xml for s in scenes]
    blobs = [pickle.dumps(s) for s in scenes]
    monkeypatch.chdir(tmp_path)
    for blob, xml in zip(blobs, expected):
        copy = pickle.loads(blob)
        assert copy.variant(9).xml == xml
    v = scenes[1].variant(4)
    w = pickle.loads(pickle.dumps(v))
    assert (w.index, w.xml, w.params, repr(w)) == (v.index, v.xml, v.params, repr(v))
    # Its patch too, a body model (the demo turns a slab) included.
    assert w.patch == v.patch and any(f == "geoms" for _, _, f, _ in w.patch)
    assert w.structure_key == v.structure_key
    # The copy's document is read back from the XML: the same model, the same text.
    assert w.document.to_xml() == v.xml
    assert w.compile().nbody == v.compile().nbody


def test_variants_are_what_the_command_lines_generate_makes(forge_cli, tmp_path):
    import io
    import json
    import subprocess
    import tarfile

    import judge

    # The demo scene has no asset files: the tar stream's XML is Python's XML, byte for
    # byte, and its JSON is Python's params (plus the member's file name).
    stream = subprocess.run(
        [str(forge_cli), "generate", "-n", "12", "--threads", "2", "-o", "-"],
        check=True, capture_output=True,
    ).stdout
    demo = Scene.load()
    with tarfile.open(fileobj=io.BytesIO(stream)) as tar:
        for i in range(12):
            assert tar.extractfile(f"{i:09d}.xml").read().decode() == demo.variant(i).xml
            line = json.loads(tar.extractfile(f"{i:09d}.json").read())
            assert line.pop("file") == f"{i:09d}.xml"
            assert line == json.loads(demo.variant(i).params_json)
    # lift5: the command line relocates asset files into the output folder (assets/ under
    # content-derived names), so the text differs; MuJoCo compiles both to the same model.
    lift5 = ROOT / "benches" / "scenes" / "lift5.toml"
    out = tmp_path / "lift5"
    subprocess.run(
        [str(forge_cli), "generate", str(lift5), "-n", "3", "--start", "40", "-o", str(out)],
        check=True, capture_output=True,
    )
    scene = Scene.load(lift5)
    manifest = [json.loads(line) for line in (out / "manifest.jsonl").read_text().splitlines()]
    assert [m["index"] for m in manifest] == [40, 41, 42]
    for line in manifest:
        v = scene.variant(line["index"])
        ours = tmp_path / f"py{v.index}.xml"
        v.write(ours)
        assert judge.compare(out / line.pop("file"), ours) == []
        assert line == json.loads(v.params_json)


@pytest.mark.parametrize(
    "case", sorted((ROOT / "corpora" / "scenes" / "errors").glob("*.toml")), ids=lambda p: p.stem
)
def test_bad_scene_files_give_the_command_lines_lines(case, monkeypatch):
    # corpora/scenes/errors/*.err are what `mjcf-forge generate CASE -n 3` prints
    # (tests/scene_batch.rs); from Python the same lines are the MjcfError's, raised by
    # the load or by the first variant that cannot be made.
    monkeypatch.chdir(ROOT)
    expected = case.with_suffix(".err").read_text().rstrip("\n").split("\n")
    with pytest.raises(MjcfError) as err:
        scene = Scene.load(os.path.relpath(case, ROOT))
        for i in range(3):
            scene.variant(i)
    assert err.value.errors == expected
    assert str(err.value) == "\n".join(expected)


# Issue 23, from the user's side: the standard exception types, numbers in params, key
# paths in the errors of a dict, progress of the variant stream.


def test_a_missing_scene_or_model_file_is_a_file_not_found_error(tmp_path):
    import errno
    import pickle

    from mjcf_forge import MjcfFileNotFoundError

    with pytest.raises(FileNotFoundError) as err:
        Scene.load(tmp_path / "missing.toml")
    e = err.value
    assert isinstance(e, MjcfFileNotFoundError) and isinstance(e, MjcfError) and isinstance(e, ValueError)
    assert e.errno == errno.ENOENT and e.filename == str(tmp_path / "missing.toml")
    assert str(e) == f"cannot read '{tmp_path / 'missing.toml'}': No such file or directory (os error 2)"
    assert e.errors == [str(e)]
    again = pickle.loads(pickle.dumps(e))
    assert type(again) is MjcfFileNotFoundError and str(again) == str(e) and again.errors == e.errors
    assert again.errno == errno.ENOENT and again.filename == e.filename
    # A model the scene names: still the scene's position, and a FileNotFoundError.
    description = tomllib.loads(DEMO_TOML.read_text())
    description["base"] = "no_such_arena.xml"
    with pytest.raises(FileNotFoundError) as err:
        Scene.from_dict(description, DEMO_DIR)
    assert err.value.errors == [
        f"<scene dict>: base: cannot read '{DEMO_DIR / 'no_such_arena.xml'}': No such file or "
        "directory (os error 2)"
    ]
    # Other problems stay MjcfError only; a file and another problem together too.
    with pytest.raises(MjcfError) as err:
        Scene.load(ROOT / "corpora" / "scenes" / "errors" / "unknown_body.toml")
    assert not isinstance(err.value, FileNotFoundError)


def test_variant_indices_are_checked_ints():
    scene = Scene.load()
    for bad in (-1, 2**64, -(2**70)):
        with pytest.raises(IndexError, match="out of range: indices run from 0 to 2\\*\\*64 - 1"):
            scene.variant(bad)
        with pytest.raises(IndexError):
            scene.variants([0, bad])
    for bad in ("3", 1.0, None, [1]):
        with pytest.raises(TypeError, match="a variant index is an int"):
            scene.variant(bad)
    assert scene.variant(np.int64(3)).xml == scene.variant(3).xml  # numpy ints are ints
    assert scene.variant(2**64 - 1).index == 2**64 - 1
    superset = scene.superset()
    for call in (superset.patch, superset.names, superset.parked):
        with pytest.raises(IndexError):
            call(-1)
        with pytest.raises(TypeError):
            call("1")


def test_params_are_numbers(demo):
    v = demo.variant(1)
    params = v.params
    doc = v.document
    for obj in params["objects"]:
        assert isinstance(obj["pos"], list) and len(obj["pos"]) == 3
        assert isinstance(obj["quat"], list) and len(obj["quat"]) == 4
        assert all(type(x) is float for x in obj["pos"] + obj["quat"])
        body = doc.find_named("body", obj["body"])
        assert obj["pos"] == [float(x) for x in body.get("pos").split()]
    kinds = set()
    for r in params["randomized"]:
        value = r["value"]
        element = doc.find_named(r["kind"], r["name"])
        # A body's mass is written on its <inertial>.
        written = element.get(r["attribute"]) or element.find("inertial").get(r["attribute"])
        if r["attribute"] == "material":  # a name stays a str
            assert value == written
            kinds.add(str)
        elif isinstance(value, list):
            assert value == [float(x) for x in written.split()] and len(value) > 1
            kinds.add(list)
        else:
            assert type(value) is float and value == float(written)
            kinds.add(float)
    assert kinds == {str, list, float}
    # params_json stays the manifest's line, values as the XML's text.
    assert json.loads(v.params_json)["objects"][0]["pos"] == " ".join(
        doc.find_named("body", params["objects"][0]["body"]).get("pos").split()
    )


def test_errors_of_a_dict_name_its_keys():
    description = tomllib.loads(DEMO_TOML.read_text())
    description["objects"][0]["placement"]["x"] = [0.1, -0.1]
    description["objects"][1]["count"] = "three"
    description["randomize"][0]["unit"] = "deg"
    with pytest.raises(MjcfError) as err:
        Scene.from_dict(description, DEMO_DIR)
    assert err.value.errors == [
        '<scene dict>: objects[1].count: invalid type: string "three", expected a count: a '
        "whole number, or [min, max]"
    ]
    description["objects"][1]["count"] = 1
    with pytest.raises(MjcfError) as err:
        Scene.from_dict(description, DEMO_DIR)
    assert "<scene dict>: objects[0].placement.x: x must be [min, max] with min <= max" in err.value.errors
    assert any(e.startswith("<scene dict>: randomize[0].unit: ") for e in err.value.errors)
    with pytest.raises(MjcfError) as err:
        Scene.from_dict({"base": "arena.xml", "fixture": [{"model": "arm.xml", "prefix": None}]}, DEMO_DIR)
    assert err.value.errors == [
        "<scene dict>: fixture[0].prefix: null (None) is not a value: leave the key out"
    ]
    # A TOML text keeps its lines and columns.
    with pytest.raises(MjcfError) as err:
        Scene.from_toml('base = "arena.xml"\nseed = "1"\n', DEMO_DIR)
    assert err.value.errors[0].endswith('<scene>:2:8: invalid type: string "1", expected u64')


def test_variants_report_progress(demo, capsys, monkeypatch):
    import types

    told = []
    got = [v.index for v in demo.variants(range(40), threads=2, window=8, progress=told.append)]
    assert got == list(range(40)) and sum(told) == 40 and all(n > 0 for n in told)
    assert len(told) < 40  # per batch handed over, not per variant

    class Bar:  # a tqdm bar of the caller's: updated, never closed
        def __init__(self):
            self.n, self.closed = 0, False

        def update(self, n):
            self.n += n

        def close(self):
            self.closed = True

    bar = Bar()
    assert len(list(demo.variants([3, 1, 2], progress=bar))) == 3
    assert bar.n == 3 and not bar.closed
    # True without tqdm: plain lines on stderr, the last one at the end.
    monkeypatch.setitem(sys.modules, "tqdm", None)
    assert len(list(demo.variants(range(5), progress=True))) == 5
    assert capsys.readouterr().err.splitlines()[-1].startswith("mjcf-forge: variants 5/5 (100%), ")
    # True with tqdm: a bar made, updated and closed.
    made = []

    class FakeTqdm(Bar):
        def __init__(self, total, **kwargs):
            super().__init__()
            self.total = total
            made.append(self)

    monkeypatch.setitem(sys.modules, "tqdm", types.SimpleNamespace(tqdm=FakeTqdm))
    assert len(list(demo.variants(range(6), progress=True))) == 6
    assert [(b.total, b.n, b.closed) for b in made] == [(6, 6, True)]
    # Off: nothing told; a failed stream closes its bar too.
    assert len(list(demo.variants(range(3), progress=False))) == 3
    with pytest.raises(TypeError):
        demo.variants(range(3), progress="yes")
