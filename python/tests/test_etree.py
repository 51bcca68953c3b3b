"""Elements that are xml.etree.ElementTree elements in behaviour.

Each behaviour is checked against xml.etree itself on the same input: robosuite's models
loaded as our Document, and the same models as xml.etree reads our Document.to_xml().
"""
from __future__ import annotations

import collections.abc
import copy
import gc
import io
import pickle
import xml.etree.ElementTree as ET

import pytest

from helpers import RS_ASSETS
from mjcf_forge import Document, Element, MjcfError, Model
from mjcf_forge import etree

PANDA = RS_ASSETS / "robots" / "panda" / "robot.xml"
TABLE = RS_ASSETS / "arenas" / "table_arena.xml"
CAN = RS_ASSETS / "objects" / "can.xml"
GRIPPER = RS_ASSETS / "grippers" / "panda_gripper.xml"
MODELS = [PANDA, TABLE, CAN]

# ElementPath queries from the root: every form ElementPath knows (tags, *, ., .., //,
# [@a], [@a='v'], [tag], [tag='text'], [n], [last()]), the common ones answered in Rust
# and the rest by xml.etree.ElementPath over our elements.
PATHS = [
    "worldbody",
    "./worldbody",
    "*",
    "./*",
    ".",
    ".//body",
    ".//joint",
    ".//geom",
    ".//*",
    ".//body[@name='link3']",
    ".//body[@name=\"link3\"]",
    ".//body[@name='object']",
    ".//site[@name='table_top']",
    ".//geom[@type='mesh']",
    ".//geom[@name][@type='box']",
    ".//body[@name]",
    ".//*[@pos]",
    "./*[@pos]",
    "worldbody/*[@pos]",
    "./worldbody/body",
    "./worldbody/body/body",
    "worldbody/body/body/body/joint",
    "worldbody//geom",
    ".//body/geom",
    ".//body//site",
    "asset/mesh",
    "asset/*[@file]",
    "actuator/*",
    ".//body/..",
    ".//joint/..",
    "..",
    ".//body[1]",
    ".//geom[2]",
    ".//body[last()]",
    ".//body[last()-1]",
    ".//geom[last()-1]",
    ".//body[geom]",
    ".//body[joint]",
    ".//body[inertial]/geom[@type='mesh']",
    ".//body[site='']",
    ".//body[@name!='link1']",
    ".//{*}body",
    "worldbody/body/",
]


def load_both(path):
    ours = Document.load(path)
    theirs = ET.fromstring(ours.to_xml())
    return ours, theirs


def shape(elements):
    return [(e.tag, e.items()) for e in elements]


@pytest.fixture(scope="module", params=MODELS, ids=lambda p: p.stem)
def both(request):
    return load_both(request.param)


def test_the_path_table_is_large_and_selects_something():
    assert len(PATHS) >= 30
    hits = {p: 0 for p in PATHS}
    for model in MODELS:
        ours = Document.load(model)
        for p in PATHS:
            hits[p] += len(ours.root.findall(p))
    # From the root: no child has a pos, no body has a sibling body, and above is nothing.
    assert [p for p, n in hits.items() if n == 0] == ["./*[@pos]", "..", ".//body[last()-1]"]


@pytest.mark.parametrize("path", PATHS)
def test_element_path_selects_what_xml_etree_selects(both, path):
    ours, theirs = both
    root = ours.root
    assert shape(root.findall(path)) == shape(theirs.findall(path))
    assert shape(root.iterfind(path)) == shape(theirs.iterfind(path))
    found, expected = root.find(path), theirs.find(path)
    assert (found is None) == (expected is None)
    if found is not None:
        assert shape([found]) == shape([expected])
    assert root.findtext(path, "none") == theirs.findtext(path, "none")
    # The document answers as ElementTree does, from the root.
    tree = ET.ElementTree(theirs)
    if not path.startswith(".."):
        assert shape(ours.findall(path)) == shape(tree.findall(path))
        assert shape(ours.iterfind(path)) == shape(tree.iterfind(path))
        assert ours.findtext(path) == tree.findtext(path)


def test_absolute_paths_from_a_document_warn_as_element_tree_does(both):
    ours, theirs = both
    with pytest.warns(FutureWarning):
        expected = shape(ET.ElementTree(theirs).findall("/worldbody"))
    with pytest.warns(FutureWarning):
        assert shape(ours.findall("/worldbody")) == expected


def test_paths_from_inner_elements_and_iter(both):
    ours, theirs = both
    for a, b in zip(ours.root.iter("body"), theirs.iter("body")):
        for path in ["geom", "./*[@pos]", ".//geom[@type='mesh']", "..", "body[1]", "*[last()]"]:
            assert shape(a.findall(path)) == shape(b.findall(path)), path
    for tag in [None, "*", "body", "geom", "nothing"]:
        assert shape(ours.root.iter(tag)) == shape(theirs.iter(tag))
        assert shape(ours.iter(tag)) == shape(ET.ElementTree(theirs).iter(tag))
    assert list(ours.root.itertext()) == list(theirs.itertext())


def test_odd_and_bad_paths_do_what_they_do_in_xml_etree():
    ours, theirs = load_both(CAN)

    def outcome(root, path):
        try:
            return shape(root.findall(path))
        except Exception as e:  # noqa: BLE001 - the kind of failure is what is compared
            return type(e)

    for path in ["/body", "worldbody/body[0]", "body[@a=1]", "body[last()+1]", "body[@a", "@a",
                 ".//", "worldbody/", "worldbody/body[1.5]", "body[", ".//body[@name='object'"]:
        assert outcome(ours.root, path) == outcome(theirs, path), path
    assert outcome(ours.root, "/body") is SyntaxError


def test_tostring_equals_xml_etree_on_robosuite_models():
    files = sorted(RS_ASSETS.glob("robots/*/robot.xml")) + sorted(RS_ASSETS.glob("arenas/*.xml"))
    files += sorted(RS_ASSETS.glob("objects/*.xml")) + sorted(RS_ASSETS.glob("grippers/*.xml"))
    compared = 0
    for f in files:
        try:
            ours, theirs = load_both(f)
        except MjcfError:
            continue
        assert ET.tostring(ours.root, encoding="unicode") == ET.tostring(theirs, encoding="unicode"), f
        world = ours.worldbody
        assert ET.tostring(world) == ET.tostring(theirs.find("worldbody")), f
        compared += 1
    assert compared >= 40
    ours, theirs = load_both(PANDA)
    out_ours, out_theirs = io.BytesIO(), io.BytesIO()
    ET.ElementTree(ours.root).write(out_ours, encoding="utf-8", xml_declaration=True)
    ET.ElementTree(theirs).write(out_theirs, encoding="utf-8", xml_declaration=True)
    assert out_ours.getvalue() == out_theirs.getvalue()
    assert ET.iselement(ours.root) and etree.iselement(ours.root) and not etree.iselement("x")


def test_our_tostring_writes_what_xml_etrees_writes():
    """mjcf_forge.etree.tostring writes our elements natively: the same text or bytes as
    xml.etree's own writer walking them, on every wheel model of robosuite's assets, for
    inner elements (their tails included) and for every encoding and declaration."""
    assert etree._NATIVE
    files = sorted(RS_ASSETS.rglob("*.xml"))
    compared = 0
    for f in files:
        try:
            ours, _ = load_both(f)
        except (MjcfError, ET.ParseError):
            continue
        for el in [ours.root, *list(ours.root)[:3]]:
            for encoding in (None, "unicode", "utf8", "utf-8", "us-ascii", "latin-1"):
                for declaration in (None, True, False):
                    got = etree.tostring(el, encoding=encoding, xml_declaration=declaration)
                    want = ET.tostring(el, encoding=encoding, xml_declaration=declaration)
                    assert got == want, (f, el.tag, encoding, declaration)
        compared += 1
    assert compared >= 50
    # Text, tails and every character either writer escapes, and non-ASCII as references.
    root = etree.fromstring("<a b='&amp;&lt;&gt;&quot;&#10;&#13;&#9;é'>x&amp;<c/>y&lt;<d e='1'>z</d>w</a>")
    for el in [root, *root]:
        for encoding in (None, "unicode", "utf8"):
            assert etree.tostring(el, encoding=encoding) == ET.tostring(el, encoding=encoding)
    assert etree.tostring(root, encoding="unicode").startswith('<a b="&amp;&lt;&gt;&quot;&#10;&#13;&#09;é">x&amp;<c />y&lt;')
    # Other options and xml.etree's own elements: xml.etree's writer.
    assert etree.tostring(root, method="html") == ET.tostring(root, method="html")
    assert etree.tostring(root, short_empty_elements=False) == ET.tostring(root, short_empty_elements=False)
    theirs = ET.fromstring("<a><b/></a>")
    assert etree.tostring(theirs) == ET.tostring(theirs)


def test_one_proxy_per_element():
    doc = Document.load(PANDA)
    a = doc.find(".//body[@name='link3']")
    assert a is doc.find_named("body", "link3") is doc.root.findall(".//body")[4]
    assert a is a.parent[a.parent[:].index(a)]
    assert doc.root is doc.getroot() is doc.root
    assert doc.worldbody[0] is doc.worldbody[0] and doc.worldbody[-1] is doc.worldbody[0]
    assert {a: 1}[doc.find(".//body[@name='link3']")] == 1
    assert next(a.iter()) is a and a in a.parent and a not in a
    # Freed proxies leave the registry; new ones are made when asked for again.
    n = len(doc.findall(".//*"))
    gc.collect()
    assert len(doc.findall(".//*")) == n


def test_attrib_is_a_live_mutable_mapping():
    doc = Document.load(PANDA)
    link1 = doc.find(".//body[@name='link1']")
    theirs = ET.fromstring(doc.to_xml()).find(".//body[@name='link1']")
    attrib = link1.attrib
    assert isinstance(attrib, collections.abc.MutableMapping)
    assert attrib == theirs.attrib and theirs.attrib == attrib and dict(attrib) == theirs.attrib
    assert not (attrib != theirs.attrib) and attrib != {"name": "x"}
    assert list(attrib) == list(theirs.attrib) and len(attrib) == len(theirs.attrib)
    assert attrib.items() == list(theirs.attrib.items()) and attrib.keys() == list(theirs.attrib)
    for e in (attrib, theirs.attrib):
        e["pos"] = "0 0 1"
        e.update({"quat": "1 0 0 0"}, user="3")
        e.setdefault("mocap", "false")
        assert e.pop("mocap") == "false" and e.pop("nothing", None) is None
        assert e.get("nothing", 5) == 5 and "pos" in e
        del e["user"]
    assert attrib == theirs.attrib and attrib.copy() == theirs.attrib
    assert repr(attrib) == repr(theirs.attrib)
    assert '<body name="link1" pos="0 0 1" quat="1 0 0 0">' in doc.to_xml()
    assert link1.get("pos") == "0 0 1" and link1.attrib is not attrib
    with pytest.raises(KeyError):
        attrib["nothing"]
    with pytest.raises(KeyError):
        del attrib["nothing"]
    with pytest.raises(TypeError):
        hash(attrib)
    link1.attrib = {"name": "link1"}
    assert link1.items() == [("name", "link1")]
    assert attrib.popitem() == ("name", "link1") and len(attrib) == 0
    attrib["name"] = "link1"
    link1.attrib.clear()
    assert link1.keys() == [] and "<body>" in doc.to_xml()


def twins():
    """The same small tree, ours and xml.etree's."""
    xml = '<body name="b"><geom name="g0"/><site name="s"/><body name="c"><joint name="j"/></body></body>'
    return etree.fromstring(xml), ET.fromstring(xml)


def test_child_edits_and_indexing_match_xml_etree():
    ours, theirs = twins()

    def same():
        assert ET.tostring(ours, encoding="unicode") == ET.tostring(theirs, encoding="unicode")

    same()
    for el, make in ((ours, Element), (theirs, ET.Element)):
        el.insert(0, make("camera", name="cam"))
        el.insert(-1, make("light", {"name": "l"}))
        el.insert(100, make("inertial", mass="1"))
        el.append(make("geom", name="g1"))
        el.extend([make("site", name="s1"), make("site", name="s2")])
        el[1] = make("geom", name="replaced")
        del el[0]
        el[2:4] = [make("a"), make("b"), make("c")]
        del el[-2:]
        el[::2] = [make(f"x{i}") for i in range(len(el[::2]))]
        el.remove(el[1])
        el.tag = "worldbody"
        el.set("pos", "1 2 3")
        el.text = "text"
        el[0].text = "inner"
        el[0].tail = "after"
    same()
    assert [e.tag for e in ours[1:4]] == [e.tag for e in theirs[1:4]]
    assert len(ours) == len(theirs) and ours[-1].tag == theirs[-1].tag
    assert list(ours.itertext()) == list(theirs.itertext())
    assert ours.findtext("x0") == theirs.findtext("x0") == "inner"
    for el in (ours, theirs):
        with pytest.raises(IndexError):
            el[len(el)]
        with pytest.raises(ValueError, match="not in list"):
            el.remove(twins()[0] if el is ours else ET.Element("x"))
        with pytest.raises(TypeError):
            el.append(1)
        with pytest.raises(ValueError):
            el[::2] = [Element("a")] if el is ours else [ET.Element("a")]
        el.clear()
    same()
    assert ours.attrib == {} and ours.text is None and len(ours) == 0


def test_truth_value_warns_as_xml_etree_and_repr():
    empty = Element("body", name="b")
    with pytest.warns(DeprecationWarning):
        assert not empty
    empty.append("geom")
    with pytest.warns(DeprecationWarning):
        assert empty
    assert repr(empty).startswith("<Element 'body' name='b' at 0x")
    assert repr(empty[0]).startswith("<Element 'geom' at 0x")
    made = empty.makeelement("site", {"name": "s"})
    assert made.attrib == {"name": "s"} and made.parent is None


def test_foreign_elements_are_copied_in():
    doc = Document.load(TABLE)
    world = doc.worldbody
    text = """
    <body name="box" pos="0 0 1">
      <!-- a comment -->
      <geom type="box" size="0.1 0.1 0.1"/>
      <site name="s" pos="0 0 0.1"/>
    </body>"""
    foreign = ET.fromstring(text)
    before = ET.tostring(foreign)
    world.append(foreign)
    box = world[-1]
    assert box.tag == "body" and box.get("name") == "box" and [k.tag for k in box] == ["geom", "site"]
    assert ET.tostring(foreign) == before  # the foreign tree is left as it was
    assert box.text is None and box[0].tail is None  # the layout's white space is not content
    assert '<body name="box" pos="0 0 1"><geom type="box" size="0.1 0.1 0.1"/>' in doc.to_xml()
    world.insert(0, ET.Element("light", {"name": "sun", "pos": "0 0 3"}))
    assert world[0].get("name") == "sun"
    world[0] = ET.Element("camera", name="cam")
    assert world[0].tag == "camera"
    with pytest.raises(TypeError):
        world.append(ET.Comment("no"))
    with pytest.raises(MjcfError):
        world.append(ET.Element("bad tag"))
    # A subtree of xml.etree's own, written by xml.etree, reads back the same.
    assert ET.tostring(box) == ET.tostring(ET.fromstring(ET.tostring(box)))


def test_same_document_append_moves_and_other_documents_are_copied():
    doc = Document.load(PANDA)
    world = doc.worldbody
    link7 = doc.find(".//body[@name='link7']")
    hand = doc.find(".//body[@name='right_hand']")
    world.append(hand)  # moved, as robosuite means it
    assert hand.parent is world and link7.find("body[@name='right_hand']") is None
    assert doc.findall(".//body[@name='right_hand']") == [hand]
    with pytest.raises(ValueError):
        hand.append(world)  # not into its own subtree
    with pytest.raises(ValueError):
        world.append(doc.root)
    other = Document.load(TABLE)
    table = other.find(".//body[@name='table']")
    leg = table.find("geom")
    world.append(table)
    assert table.parent is world and leg.parent is table  # the handles follow the copy
    table.set("pos", "9 9 9")
    assert 'name="table" pos="9 9 9"' in doc.to_xml() and "9 9 9" not in other.to_xml()
    # ElementTree would have one element in both trees: the other document's handles to
    # the copied subtree are the copies' from now on (its text stays as it was).
    assert other.find(".//body[@name='table']") is table
    assert other.find(".//body[@name='table']/geom") is leg


def test_an_element_appended_from_another_document_is_found_there_as_its_copy():
    """robosuite's RobotModel.add_leg_base appends the base's bodies into the robot, finds
    the base's support body again in the base's tree, and moves the arm into it."""
    robot = Document.from_string(
        '<mujoco><worldbody><body name="root"><body name="arm"/></body></worldbody></mujoco>')
    base = Document.from_string(
        '<mujoco><worldbody><body name="legs"><freejoint/><body name="support"/></body></worldbody></mujoco>')
    root = robot.find(".//body[@name='root']")
    arm = root.find("body")
    for body in base.worldbody:
        root.append(body)  # copied into the robot
    support = base.find(".//body[@name='support']")  # looked up in the base's tree
    assert support.parent.parent is root
    free = base.worldbody.find(".//freejoint")
    free.parent.remove(free)
    support.append(copy.deepcopy(arm))
    root.remove(arm)
    assert robot.to_xml() == ('<mujoco><worldbody><body name="root"><body name="legs">'
                              '<body name="support"><body name="arm"/></body></body></body></worldbody></mujoco>')
    assert "freejoint" in base.to_xml()  # the base's own text is untouched


def test_removed_elements_are_detached_not_dead():
    doc = Document.load(PANDA)
    link6 = doc.find(".//body[@name='link6']")
    joint = link6.find("joint")
    parent = link6.parent
    parent.remove(link6)
    assert link6.parent is None and joint.parent is link6
    assert doc.find(".//body[@name='link6']") is None and 'name="link6" pos' not in doc.to_xml()
    link6.set("pos", "1 1 1")  # edits the detached element, not the document
    assert "1 1 1" not in doc.to_xml() and link6.get("pos") == "1 1 1"
    assert ET.tostring(link6).startswith(b'<body name="link6" pos="1 1 1" quat=')
    with pytest.raises(ValueError):
        parent.remove(link6)
    parent.append(link6)  # and back again
    assert link6.parent is parent and 'name="link6" pos="1 1 1"' in doc.to_xml()
    del parent[-1]
    assert link6.parent is None
    with pytest.raises(MjcfError):
        link6.tail = "no parent"
    link6.remove()  # no parent: nothing to do
    doc.worldbody.clear()
    assert len(doc.worldbody) == 0 and doc.find(".//body") is None


def test_copies_are_detached_element_trees():
    doc = Document.load(PANDA)
    link1 = doc.find(".//body[@name='link1']")
    theirs = ET.fromstring(doc.to_xml()).find(".//body[@name='link1']")
    for copier in (copy.copy, copy.deepcopy):
        twin = copier(link1)
        assert twin is not link1 and twin.parent is None
        assert ET.tostring(twin) == ET.tostring(copier(theirs))
        twin.set("name", "twin")
        assert link1.get("name") == "link1"
        doc.worldbody.append(twin)  # copied in; the handle follows
        assert twin.parent is doc.worldbody
        assert doc.find(".//body[@name='twin']") is twin
        twin.attrib["name"] = "gone"
        doc.worldbody.remove(twin)


def test_elements_pickle_as_xml_etrees_do():
    doc = Document.from_string(
        '<mujoco><custom><text name="t" data="a &amp; b"/>x<numeric name="n"/>tail</custom>'
        '<worldbody><body name="b" pos="0 0 1"><geom size="1"/></body></worldbody></mujoco>'
    )
    doc.find(".//numeric").text = "1 < 2"
    theirs = ET.fromstring(doc.to_xml())
    for path in [".//body", "custom", ".//text", ".//numeric"]:
        ours = doc.find(path)
        back = pickle.loads(pickle.dumps(ours))
        their_back = pickle.loads(pickle.dumps(theirs.find(path)))
        assert isinstance(back, Element) and back.parent is None and back is not ours
        their_back.tail = None  # a detached element of ours has no tail (as its copies)
        assert ET.tostring(back) == ET.tostring(their_back), path
        assert back.text == their_back.text and back.tail is None, path
    # Into another process's document: appended like any new element.
    body = pickle.loads(pickle.dumps(doc.find(".//body")))
    other = Document.from_string("<mujoco><worldbody/></mujoco>")
    other.worldbody.append(body)
    assert body.parent is other.worldbody and other.find(".//geom").get("size") == "1"


def test_text_and_tail_read_and_write_as_xml_etree():
    doc = Document.from_string('<mujoco><custom><numeric name="n" data="1"/></custom><size/></mujoco>')
    custom, numeric = doc.find("custom"), doc.find(".//numeric")
    assert custom.text is None and numeric.tail is None and doc.root.text is None
    custom.text = "hello"
    numeric.tail = " world"
    numeric.text = "x < y"
    theirs = ET.fromstring(doc.to_xml())
    assert theirs.find("custom").text == "hello" and theirs.find(".//numeric").tail == " world"
    assert ET.tostring(doc.root) == ET.tostring(theirs)
    assert list(doc.root.itertext()) == list(theirs.itertext())
    for path in ["custom[numeric='x < y']", ".//*[.='x < y']", "*[numeric='no']", ".//numeric[.!='a']"]:
        assert shape(doc.root.findall(path)) == shape(theirs.findall(path)), path
    assert doc.findtext("custom/numeric") == "x < y" and doc.findtext("size") == ""
    numeric.text = None
    assert doc.find(".//numeric").text is None


def test_handles_stay_live_across_document_merges():
    scene = Document.load(TABLE)
    robot = Document.load(PANDA)
    robot.prefix("robot0_")
    hand = robot.find(".//body[@name='robot0_right_hand']")
    joint = robot.find(".//joint[@name='robot0_joint1']")
    table = scene.find(".//body[@name='table']")
    scene.merge(robot, part_prefix="robot0_")
    assert scene.find(".//body[@name='robot0_right_hand']") is hand
    assert scene.find(".//joint[@name='robot0_joint1']") is joint and table.parent is scene.worldbody
    hand.set("pos", "0 0 0.5")
    assert 'name="robot0_right_hand" pos="0 0 0.5"' in scene.to_xml()
    assert 'pos="0 0 0.5"' not in robot.to_xml()  # the part is left as it was
    # Elements appended under a merged handle go to the merged document.
    hand.append(Element("site", name="robot0_tip", size="0.01"))
    assert scene.find(".//site[@name='robot0_tip']").parent is hand


def test_handles_stay_live_across_model_merges_and_the_model_document_is_live():
    robot = Model(PANDA, "robot0")
    gripper = Model(GRIPPER, "gripper0")
    doc = robot.document
    assert doc.root is robot.document.root  # one document, one proxy per element
    hand = doc.find(".//body[@name='robot0_right_hand']")
    finger = gripper.document.find(".//body[@name='gripper0_leftfinger']")
    robot.merge(gripper, body="robot0_right_hand")
    ancestors = []
    up = finger.parent
    while up is not None:
        ancestors.append(up)
        up = up.parent
    assert hand in ancestors and ancestors[-1] is doc.root
    assert robot.document.find(".//body[@name='gripper0_leftfinger']") is finger
    finger.set("pos", "0 0.5 0")
    assert 'name="gripper0_leftfinger" pos="0 0.5 0"' in robot.to_xml()
    base = doc.find(".//body[@name='robot0_base']")
    base.attrib["pos"] = "-0.5 0 0.9"
    assert 'name="robot0_base" pos="-0.5 0 0.9"' in robot.to_xml()
    # Model(document) copies it: later edits to the document stay out of the model.
    source = Document.load(CAN)
    can = Model(source, "obj")
    source.find(".//body").set("pos", "7 7 7")
    assert "7 7 7" not in can.to_xml()


def test_the_etree_module_mirrors_xml_etree():
    body = etree.Element("body", {"name": "cube"}, pos="0 0 1")
    geom = etree.SubElement(body, "geom", type="box", size="0.1 0.1 0.1")
    theirs = ET.Element("body", {"name": "cube"}, pos="0 0 1")
    ET.SubElement(theirs, "geom", type="box", size="0.1 0.1 0.1")
    assert isinstance(body, Element) and geom.parent is body
    assert etree.tostring(body, encoding="unicode") == ET.tostring(theirs, encoding="unicode")
    foreign_child = etree.SubElement(theirs, "site", name="s")
    assert isinstance(foreign_child, ET.Element)
    ours = etree.fromstring(PANDA.read_text())
    assert ET.tostring(ours) == ET.tostring(etree.XML(ET.tostring(ET.parse(PANDA).getroot())))
    tree = etree.parse(PANDA)
    assert isinstance(tree.getroot(), Element) and tree.getroot().tag == "mujoco"
    assert shape(tree.findall(".//joint")) == shape(ET.parse(PANDA).findall(".//joint"))
    out = io.StringIO()
    etree.ElementTree(body).write(out, encoding="unicode")
    assert out.getvalue() == ET.tostring(body, encoding="unicode")
    doc = Document.load(TABLE)
    doc.worldbody.append(body)  # a new element joins a document: copied, handle follows
    assert body.parent is doc.worldbody and doc.find(".//body[@name='cube']/geom") is geom
    with pytest.raises(etree.ParseError):
        etree.fromstring("<a>")
