#!/usr/bin/env python3
"""Generate src/document/vocab.rs: the MJCF vocabulary table of mjcf-forge.

Inputs (both required, neither is committed):

* the element tree that the pinned MuJoCo prints about itself,
  ``mujoco.mj_printSchema(False, True)``, run live in a Python that has
  ``mujoco==PINNED_MUJOCO`` installed (``--python``). It decides which
  elements and attributes exist.
* a local copy of MuJoCo's ``src/xml/mjcf.schema`` (``--schema``). It decides
  the kinds (``id<ns>`` / ``ref<ns>`` / ``file`` / ``(nodefault)``) and the
  contexts (which schema element a tag means under which parent).

Usage::

    python3 -m venv /tmp/vv && /tmp/vv/bin/pip install mujoco==3.17.0
    python3 scripts/gen_vocab.py --schema /tmp/mjcf.schema \\
        --schema-rev <mujoco commit of the schema copy> \\
        --python /tmp/vv/bin/python [--out src/document/vocab.rs]

The script prints a report (differences between the two inputs, counts) on
stderr and formats the output with rustfmt when it is on PATH.
"""

from __future__ import annotations

import argparse
import hashlib
import re
import shutil
import subprocess
import textwrap
import sys
from dataclasses import dataclass, field
from pathlib import Path

PINNED_MUJOCO = "3.17.0"
SCHEMA_PATH_IN_MUJOCO = "src/xml/mjcf.schema"

# Namespace order of the generated `Ns` enum (it derives Ord); namespaces the
# schema declares beyond these are appended alphabetically.
NS_ORDER = [
    "body", "joint", "geom", "site", "camera", "light", "frame", "mesh",
    "hfield", "skin", "texture", "material", "model", "tendon", "actuator",
    "sensor", "equality", "pair", "exclude", "flex", "key", "numeric", "text",
    "tuple", "default", "instance",
]

# <default> slots, in enum order.
SLOTS = [
    "mesh", "texture", "material", "joint", "geom", "site", "camera", "light",
    "pair", "equality", "tendon", "actuator",
]
# Elements whose class slot is named after their parent container, not their tag.
SLOT_BY_PARENT = {"equality": "equality", "tendon": "tendon", "actuator": "actuator"}

# Kinds decided here rather than read from the schema. Key: (schema element,
# attribute); value: (kind, comment). Kind syntax: Plain, File, Id:ns, Ref:ns,
# RefList:ns.
KIND_OVERRIDES = {
    # The schema types these `string`; they hold space-separated body names.
    ("flex", "body"): ("RefList:body", "space-separated body names (schema: string)"),
    ("flex", "node"): ("RefList:body", "space-separated body names (schema: string)"),
    # The schema says ref<model>, but <mujoco model="..."> is the document's own
    # name: nothing declares it, and renaming or resolving it would be wrong.
    ("mujoco", "model"): ("Plain", "the model's own name (schema: ref<model>)"),
}

# Attributes present in the pinned MuJoCo but absent from the schema that are
# obviously names/refs/files (checked against MuJoCo 3.17.0's error messages).
EXTRA_KINDS = {
    ("site", "mesh"): ("Ref:mesh", "mesh asset name"),
    ("composite_site", "mesh"): ("Ref:mesh", "mesh asset name, as site's"),
    ("flexcomp", "mesh"): ("Ref:mesh", "mesh asset name"),
}

# Value types decided here rather than read from the schema, where the pinned MuJoCo (or
# 4.0.0) accepts more than the schema revision says. Key: (schema element, attribute).
VALUE_OVERRIDES: dict[tuple[str, str], str] = {}

# Polymorphic name pairs: type keyword attribute -> name attribute.
OBJ_PAIRS = {"objtype": "objname", "reftype": "refname"}


def die(msg: str) -> None:
    sys.exit(f"gen_vocab: error: {msg}")


def warn(msg: str) -> None:
    print(f"gen_vocab: {msg}", file=sys.stderr)


# ----------------------------------------------------------------------------------------------
# mjcf.schema


@dataclass
class SAttr:
    name: str
    type: str
    facets: dict[str, str]


@dataclass
class SElement:
    name: str
    tag: str
    alias: str | None
    attrs: list[SAttr] = field(default_factory=list)
    children: list[tuple[str, str]] = field(default_factory=list)


def strip_comment(line: str) -> str:
    out, quoted = [], False
    for ch in line:
        if ch == '"':
            quoted = not quoted
        elif ch == "#" and not quoted:
            break
        out.append(ch)
    return "".join(out).strip()


def parse_facets(text: str | None) -> dict[str, str]:
    facets: dict[str, str] = {}
    if not text:
        return facets
    for part in re.findall(r'(?:[^,"]|"[^"]*")+', text):
        part = part.strip()
        if not part:
            continue
        key, _, value = part.partition("=")
        facets[key.strip()] = value.strip()
    return facets


ATTR_RE = re.compile(
    r"^(\w+)\s*:\s*([\w<>\[\].*]+)(?:\s*=\s*(\{[^}]*\}|[^\s(]+))?\s*(?:\((.*)\))?$"
)
ELEM_RE = re.compile(r"^element\s+(\w+)\s*(?::\s*(\w+))?\s*(?:\((.*)\))?\s*\{$")
GROUP_RE = re.compile(r"^group\s+(\w+)(?:\s+variant)?\s*\{$")


ENUM_RE = re.compile(r"^enum\s+(\w+)\s*(?::\s*\w+)?\s*\{$")
ENUM_KEY_RE = re.compile(r'^("[^"]*"|\S+)\s*=')

# The symbolic bounds of counts (`double[1..mjNREF]`), checked against the pinned MuJoCo.
SYMBOLIC_COUNTS = {"mjNREF": 2, "mjNIMP": 5, "mjNDYN": 10, "mjNGAIN": 10, "mjNBIAS": 10}

# Keywords of each schema enum, in declaration order.
ENUMS: dict[str, list[str]] = {}


def parse_schema(text: str) -> tuple[dict[str, SElement], set[str]]:
    groups: dict[str, list[SAttr]] = {}
    elements: dict[str, SElement] = {}
    namespaces: set[str] = set()
    block: tuple[str, object] | None = None  # ("enum"|"group"|"element", payload)
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = strip_comment(raw)
        if not line:
            continue
        if block is None:
            if m := ENUM_RE.match(line):
                ENUMS[m[1]] = []
                block = ("enum", ENUMS[m[1]])
            elif m := GROUP_RE.match(line):
                groups[m[1]] = []
                block = ("group", groups[m[1]])
            elif m := ELEM_RE.match(line):
                facets = parse_facets(m[3])
                el = SElement(m[1], facets.get("xml", m[1]), facets.get("alias"))
                if el.name in elements:
                    die(f"schema line {lineno}: element {el.name} declared twice")
                elements[el.name] = el
                block = ("element", el)
            else:
                die(f"schema line {lineno}: cannot parse {line!r}")
            continue
        if line == "}":
            block = None
            continue
        kind, payload = block
        if kind == "enum":
            km = ENUM_KEY_RE.match(line)
            if not km:
                die(f"schema line {lineno}: cannot parse enum key {line!r}")
            payload.append(km[1].strip('"'))
            continue
        words = line.split()
        if words[0] in ("exclusive", "together", "requires", "oneof", "set"):
            continue
        if kind == "element" and words[0] == "use":
            if words[1] not in groups:
                die(f"schema line {lineno}: unknown group {words[1]}")
            payload.attrs.extend(groups[words[1]])
            continue
        if kind == "element" and words[0] == "child":
            payload.children.append((words[1], words[2]))
            continue
        m = ATTR_RE.match(line)
        if not m:
            die(f"schema line {lineno}: cannot parse {line!r}")
        attr = SAttr(m[1], m[2], parse_facets(m[4]))
        if nm := re.fullmatch(r"(?:id|ref)<(\w+)>", attr.type):
            namespaces.add(nm[1])
        target = payload.attrs if kind == "element" else payload
        target.append(attr)
    if block is not None:
        die("schema: unterminated block")
    for el in elements.values():
        names = [a.name for a in el.attrs]
        if len(names) != len(set(names)):
            die(f"schema: element {el.name} has a duplicate attribute")
    return elements, namespaces


def schema_kind(attr: SAttr) -> str:
    if m := re.fullmatch(r"id<(\w+)>", attr.type):
        return f"Id:{m[1]}"
    if m := re.fullmatch(r"ref<(\w+)>", attr.type):
        return f"Ref:{m[1]}"
    if attr.type == "file":
        return "File"
    return "Plain"


def value_type(attr: SAttr | None) -> str:
    """What MuJoCo's reader accepts as the attribute's value, as `Value` syntax:
    `Text` (not checked), `Reals:min:max`, `Ints:min:max` (max `MANY` = unbounded),
    `Keyword:<enum>`."""
    if attr is None:
        return "Text"  # not in the schema: nothing known of its value
    t = attr.type
    custom = attr.facets.get("reading") == "custom"
    if t == "bool":
        return "Keyword:bool"
    if m := re.fullmatch(r"enum<(\w+)>", t):
        # Hand-read enums may take more than their keywords (general's `input`).
        if custom or m[1] not in ENUMS:
            return "Text"
        return f"Keyword:{m[1]}"
    m = re.fullmatch(r"(double|float|int)(?:\[(?:(\w+)(?:\.\.(\w+))?)?\])?", t)
    if not m:
        return "Text"  # string, file, chars, flags, id, ref
    head = "Ints" if m[1] == "int" else "Reals"
    if "[" not in t:
        lo = hi = "1"
    elif m[2] is None:
        lo, hi = "0", "MANY"
    else:
        lo, hi = m[2], m[3] or m[2]
    bounds = []
    for b in (lo, hi):
        if b == "MANY" or b.isdigit():
            bounds.append(b)
        elif b in SYMBOLIC_COUNTS:
            bounds.append(str(SYMBOLIC_COUNTS[b]))
        else:
            die(f"attribute {attr.name}: unknown count bound {b}")
    return f"{head}:{bounds[0]}:{bounds[1]}"


# ----------------------------------------------------------------------------------------------
# mj_printSchema


@dataclass
class PNode:
    name: str
    card: str
    attrs: list[str]
    children: list["PNode"] = field(default_factory=list)


PRINT_HEAD_RE = re.compile(r"^( *)(\S+) \((.)\)(?:\s+(.*))?$")


def run_print_schema(python: str) -> tuple[str, str]:
    code = (
        "import mujoco, sys\n"
        "sys.stdout.write(mujoco.__version__ + '\\n')\n"
        "sys.stdout.write(mujoco.mj_printSchema(False, True))\n"
    )
    try:
        out = subprocess.run(
            [python, "-c", code], check=True, capture_output=True, text=True
        ).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        die(f"running mj_printSchema with {python}: {e}")
    version, _, tree = out.partition("\n")
    return version.strip(), tree


def parse_print_schema(text: str) -> PNode:
    stack: list[tuple[int, PNode]] = []
    root: PNode | None = None
    for lineno, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        indent = len(line) - len(line.lstrip(" "))
        m = PRINT_HEAD_RE.match(line)
        if indent >= 30 or not m:
            if not stack or indent < 30:
                die(f"printSchema line {lineno}: cannot parse {line!r}")
            stack[-1][1].attrs.extend(line.split())
            continue
        node = PNode(m[2], m[3], (m[4] or "").split())
        while stack and stack[-1][0] >= indent:
            stack.pop()
        if stack:
            stack[-1][1].children.append(node)
        elif root is None:
            root = node
        else:
            die(f"printSchema line {lineno}: second root {node.name}")
        stack.append((indent, node))
    if root is None or root.name != "mujoco":
        die("printSchema: no <mujoco> root")
    return root


# ----------------------------------------------------------------------------------------------
# Merge


@dataclass
class Attr:
    name: str
    kind: str
    nodefault: bool
    comment: str = ""
    value: str = "Text"


@dataclass
class Element:
    name: str
    tag: str
    src: str | None  # schema element supplying kinds
    attr_names: list[str]
    children: list[str] = field(default_factory=list)
    default_row: bool = False
    parents: set[str] = field(default_factory=set)
    attrs: list[Attr] = field(default_factory=list)
    slot: str | None = None


class Builder:
    def __init__(self, schema: dict[str, SElement]):
        self.schema = schema
        self.out: dict[str, Element] = {}
        self.notes: list[str] = []

    def tag_of(self, name: str) -> str:
        return self.schema[name].tag

    def resolve(self, parent: Element, tag: str) -> tuple[str, str | None, bool]:
        """(our name, schema source, is default row) of child `tag` under `parent`."""
        if parent.name == "mujoco" and tag == "(world)body":
            return "body", "body", False
        if parent.name == "default":
            if tag == "default":
                return "default", "default", False
            src = None
            for cname, _ in self.schema["default"].children:
                if cname != "default" and self.tag_of(cname) == tag:
                    src = cname
            if src is None:
                src = self.primary_by_tag(tag, f"default row <{tag}>")
            return f"default_{tag}", src, True
        src = parent.src
        if src is not None:
            hits = [c for c, _ in self.schema[src].children if self.tag_of(c) == tag]
            if len(hits) == 1:
                return hits[0], hits[0], False
        name = self.primary_by_tag(tag, f"<{tag}> under {parent.name}")
        return name, name, False

    def primary_by_tag(self, tag: str, what: str) -> str:
        hits = [n for n, e in self.schema.items() if e.name == tag]
        if len(hits) != 1:
            hits = [n for n, e in self.schema.items() if e.tag == tag]
        if len(hits) != 1:
            die(f"{what}: cannot resolve against mjcf.schema (candidates {hits})")
        self.notes.append(f"{what}: not a schema child; taken as schema element {hits[0]}")
        return hits[0]

    def add(self, node: PNode, parent: Element | None) -> Element:
        if parent is None:
            name, src, drow = "mujoco", "mujoco", False
        else:
            name, src, drow = self.resolve(parent, node.name)
        tag = node.name if node.name != "(world)body" else "body"
        el = self.out.get(name)
        if el is None:
            el = Element(name, tag, src, list(node.attrs), default_row=drow)
            self.out[name] = el
        elif sorted(el.attr_names) != sorted(node.attrs):
            die(f"element {name} printed with two attribute sets")
        if parent is not None:
            el.parents.add(parent.name)
        if node.card == "R" and name not in el.children:
            el.children.append(name)
        for child in node.children:
            c = self.add(child, el)
            if c.name not in el.children:
                el.children.append(c.name)
        return el

    def add_aliases(self) -> None:
        """worldbody, frame and replicate: body's grammar row, not printed by MuJoCo."""
        body = self.out["body"]
        for i, alias in enumerate(("frame", "replicate"), 1):
            if alias not in body.children:
                body.children.insert(body.children.index("body") + i, alias)
        for alias in ("worldbody", "frame", "replicate"):
            s = self.schema[alias]
            if s.alias != "body":
                die(f"schema: {alias} is not an alias of body")
            el = Element(alias, alias, alias, [a.name for a in s.attrs])
            el.children = list(body.children)
            self.out[alias] = el
        mujoco = self.out["mujoco"]
        mujoco.children[mujoco.children.index("body")] = "worldbody"
        self.out["worldbody"].parents.add("mujoco")
        body.parents.discard("mujoco")
        for name in ("body", "frame", "replicate"):
            self.out["frame"].parents.add(name)
            self.out["replicate"].parents.add(name)
        self.out["frame"].parents.add("worldbody")
        self.out["replicate"].parents.add("worldbody")

    def slot_of(self, el: Element) -> str | None:
        if el.default_row:
            if el.tag in ("equality", "tendon"):
                return el.tag
            primary = self.out.get(el.src)
            if primary is None or primary.default_row:
                die(f"default row {el.name}: no primary element {el.src}")
            return self.slot_of(primary)
        if "class" not in el.attr_names or el.name == "default":
            return None
        via = {SLOT_BY_PARENT[p] for p in el.parents if p in SLOT_BY_PARENT}
        slot = via.pop() if len(via) == 1 else el.tag
        if slot not in SLOTS:
            die(f"{el.name} has `class` but no known <default> slot ({slot})")
        return slot

    def default_row_of(self, el: Element) -> Element | None:
        if el.default_row or el.slot is None:
            return None
        if el.slot in ("equality", "tendon"):
            return self.out.get(f"default_{el.slot}")
        return self.out.get(f"default_{el.tag}")

    def finish(self) -> None:
        for el in self.out.values():
            el.slot = self.slot_of(el)
        for el in self.out.values():
            self.finish_attrs(el)

    def finish_attrs(self, el: Element) -> None:
        s = self.schema[el.src] if el.src else None
        sattrs = {a.name: a for a in s.attrs} if s else {}
        order = [a.name for a in s.attrs] if s else []
        names = [n for n in order if n in el.attr_names]
        names += [n for n in el.attr_names if n not in order]
        if "class" in names and "class" not in order and "name" in names:
            names.remove("class")
            names.insert(names.index("name") + 1, "class")
        drow = self.default_row_of(el)
        for n in names:
            comment = ""
            if n in sattrs:
                kind = schema_kind(sattrs[n])
                nodefault = "nodefault" in sattrs[n].facets
            elif (el.src, n) in EXTRA_KINDS:
                kind, why = EXTRA_KINDS[(el.src, n)]
                comment = f"3.17.0-only (absent from mjcf.schema): {why}"
                nodefault = False
            elif n == "class":
                kind, nodefault = "Ref:default", False
                comment = "3.17.0-only (absent from mjcf.schema): default class name"
            else:
                kind, nodefault = "Plain", False
                comment = "3.17.0-only (absent from mjcf.schema)"
            if (el.src, n) in KIND_OVERRIDES:
                kind, why = KIND_OVERRIDES[(el.src, n)]
                comment = why
            if n in OBJ_PAIRS and OBJ_PAIRS[n] in names:
                kind = f"ObjType:{OBJ_PAIRS[n]}"
            elif n in OBJ_PAIRS.values() and any(
                v == n and k in names for k, v in OBJ_PAIRS.items()
            ):
                kind = "ObjName"
            if el.default_row:
                nodefault = False
            elif drow is not None and n not in ("name", "class") and n not in drow.attr_names:
                if not nodefault:
                    self.notes.append(
                        f"nodefault derived: {el.name}.{n} (absent from <default> row {drow.name})"
                    )
                nodefault = True
            elif drow is not None and nodefault and n in drow.attr_names:
                self.notes.append(
                    f"schema says nodefault but 3.17.0's <default> row has it: {el.name}.{n}"
                )
                nodefault = False
            value = value_type(sattrs.get(n))
            if (el.src, n) in VALUE_OVERRIDES:
                value = VALUE_OVERRIDES[(el.src, n)]
            el.attrs.append(Attr(n, kind, nodefault, comment, value))


def build(schema: dict[str, SElement], tree: PNode) -> Builder:
    b = Builder(schema)
    b.add(tree, None)
    if "include" in b.out:
        del b.out["include"]
    b.add_aliases()
    b.finish()
    return b


def shortcut_params(b: Builder) -> dict[str, list[str]]:
    """Attributes of each actuator shortcut that <general> does not have (plus inheritrange)."""
    general = set(b.out["general"].attr_names) - {"inheritrange"}
    out = {}
    for name in b.out["actuator"].children:
        el = b.out[name]
        if name in ("general",) or el.tag == "plugin":
            continue
        out[el.tag] = [a.name for a in el.attrs if a.name not in general]
    return out


# ----------------------------------------------------------------------------------------------
# Rust output


def camel(s: str) -> str:
    return "".join(p.capitalize() for p in s.split("_"))


def rust_value(value: str) -> str:
    head, *args = value.split(":")
    if head == "Text":
        return "Text"
    if head == "Keyword":
        return f"Keyword(KW_{args[0].upper()})"
    return f"{head}({args[0]}, {args[1]})"


def check_symbolic_counts(python: str) -> None:
    code = "import mujoco; print(' '.join(str(getattr(mujoco, n)) for n in %r))" % (
        list(SYMBOLIC_COUNTS),)
    out = subprocess.run([python, "-c", code], check=True, capture_output=True, text=True)
    live = [int(v) for v in out.stdout.split()]
    if live != list(SYMBOLIC_COUNTS.values()):
        die(f"symbolic counts {SYMBOLIC_COUNTS} differ from MuJoCo's {live}")


def rust_kind(kind: str) -> str:
    head, _, arg = kind.partition(":")
    if head in ("Plain", "File", "ObjName"):
        return head
    if head == "ObjType":
        return f'ObjType {{ name_attr: "{arg}" }}'
    return f"{head}(Ns::{camel(arg)})"


def report(b: Builder, schema: dict[str, SElement], tree_text: str) -> list[str]:
    lines = []
    for el in sorted(b.out.values(), key=lambda e: e.name):
        if el.src and el.src in schema and not el.default_row:
            missing = [a.name for a in schema[el.src].attrs if a.name not in el.attr_names]
            if missing and el.name != "worldbody":
                lines.append(f"in mjcf.schema, not in {PINNED_MUJOCO}: {el.name}: {' '.join(missing)}")
        extra = [a.name for a in el.attrs if a.comment.startswith("3.17.0-only")]
        if extra:
            lines.append(f"in {PINNED_MUJOCO}, not in mjcf.schema: {el.name}: {' '.join(extra)}")
    used = {e.src for e in b.out.values()}
    unused = sorted(n for n in schema if n not in used)
    if unused:
        lines.append(f"schema elements not in {PINNED_MUJOCO}: {' '.join(unused)}")
    return lines + b.notes


def emit(b: Builder, namespaces: list[str], args, schema_sha: str) -> str:
    els = sorted(b.out.values(), key=lambda e: e.name)
    index = {e.name: i for i, e in enumerate(els)}
    n_attrs = sum(len(e.attrs) for e in els)
    counts: dict[str, int] = {}
    for e in els:
        for a in e.attrs:
            h = a.kind.partition(":")[0]
            counts[h] = counts.get(h, 0) + 1
    rev = args.schema_rev or "unrecorded revision"
    o: list[str] = []
    w = o.append
    w("// @generated by scripts/gen_vocab.py -- do not edit by hand.")
    w("//")
    w("// Inputs:")
    w(f"// - MuJoCo {PINNED_MUJOCO}: `mujoco.mj_printSchema(False, True)`, run live (which elements and")
    w("//   attributes exist).")
    w(f"// - google-deepmind/mujoco `{SCHEMA_PATH_IN_MUJOCO}` at {rev}")
    w(f"//   (sha256 {schema_sha}):")
    w("//   attribute kinds (id/ref/file/nodefault), value types and contexts.")
    w("// Regenerate:")
    w(f"//   python3 -m venv /tmp/vv && /tmp/vv/bin/pip install mujoco=={PINNED_MUJOCO}")
    w("//   # save mjcf.schema of that revision to /tmp/mjcf.schema, then:")
    w("//   python3 scripts/gen_vocab.py --schema /tmp/mjcf.schema --schema-rev <rev> \\")
    w("//       --python /tmp/vv/bin/python --out src/document/vocab.rs")
    w("")
    w("//! The MJCF vocabulary: every element kind and attribute MuJoCo")
    w(f"//! {PINNED_MUJOCO} accepts, with what each attribute holds as far as names and files go.")
    w("//!")
    w("//! Element kinds are the schema's elements, so one XML tag can mean several kinds by")
    w("//! context (a `<joint>` in `<equality>` is `equality_joint`); [`child`] resolves a tag")
    w("//! under a parent kind. The children of `<default>` are their own kinds")
    w("//! (`default_geom`, ...): the settable rows of each default slot.")
    w("//!")
    w(f"//! {len(els)} element kinds, {n_attrs} attribute rows (by kind: "
      + ", ".join(f"{k} {counts[k]}" for k in sorted(counts)[:4]) + ",")
    w("//! " + ", ".join(f"{k} {counts[k]}" for k in sorted(counts)[4:]) + ").")
    w("")
    w("/// A name namespace of MJCF (the `ns` of `id<ns>` / `ref<ns>` in MuJoCo's schema).")
    w("#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]")
    w("pub enum Ns {")
    for ns in namespaces:
        w(f"    /// Names declared by `id<{ns}>`.")
        w(f"    {camel(ns)},")
    w("}")
    w("")
    w("impl Ns {")
    w("    /// The namespace's name in MuJoCo's schema (e.g. `\"body\"`).")
    w("    pub fn as_str(self) -> &'static str {")
    w("        match self {")
    for ns in namespaces:
        w(f'            Ns::{camel(ns)} => "{ns}",')
    w("        }")
    w("    }")
    w("}")
    w("")
    w("/// What an attribute holds, as far as names and files go.")
    w("#[derive(Clone, Copy, Debug, PartialEq, Eq)]")
    w("pub enum AttrKind {")
    w("    /// Anything else: numbers, keywords, free text.")
    w("    Plain,")
    w("    /// Declares the element's name in a namespace (`id<ns>`).")
    w("    Id(Ns),")
    w("    /// Names one object of a namespace (`ref<ns>`).")
    w("    Ref(Ns),")
    w("    /// Space-separated list of names of one namespace (e.g. flex `body`, `node`).")
    w("    RefList(Ns),")
    w("    /// A file path resolved against the compiler's directories.")
    w("    File,")
    w("    /// Object type keyword for a sibling [`AttrKind::ObjName`] attribute (`objtype`, `reftype`).")
    w("    ObjType {")
    w("        /// The name of the sibling attribute holding the object's name.")
    w("        name_attr: &'static str,")
    w("    },")
    w("    /// A name whose namespace is given by the sibling [`AttrKind::ObjType`] attribute.")
    w("    ObjName,")
    w("}")
    w("")
    w("/// One attribute of one element kind.")
    w("#[derive(Clone, Copy, Debug)]")
    w("pub struct AttrSpec {")
    w("    /// The attribute's name.")
    w("    pub name: &'static str,")
    w("    /// What the attribute holds.")
    w("    pub kind: AttrKind,")
    w("    /// Not settable in a `<default>` class: the schema's `(nodefault)`, or absent from the")
    w(f"    /// element's `<default>` row in MuJoCo {PINNED_MUJOCO}. Always false in default rows.")
    w("    pub nodefault: bool,")
    w("    /// What MuJoCo's reader accepts as its value (the schema's type).")
    w("    pub value: Value,")
    w("}")
    w("")
    w("/// Count bound of [`Value::Reals`] and [`Value::Ints`]: any number of values.")
    w("pub const MANY: u16 = u16::MAX;")
    w("")
    w("/// What an attribute's value must be, from the schema's type (`double[3]`, `int`,")
    w("/// `enum<geomtype>`, ...). Counts are of white-space separated values; an empty value")
    w("/// (no values at all) is always accepted for numbers, as MuJoCo does.")
    w("#[derive(Clone, Copy, Debug, PartialEq, Eq)]")
    w("pub enum Value {")
    w("    /// Not checked: names, files, free text, flags, and what the schema does not type.")
    w("    Text,")
    w("    /// From `.0` to `.1` real numbers (`double`, `float`).")
    w("    Reals(u16, u16),")
    w("    /// From `.0` to `.1` integers (`int`), each within `i32`.")
    w("    Ints(u16, u16),")
    w("    /// Exactly one of these keywords (`bool`, `enum<...>`), compared byte for byte.")
    w("    Keyword(&'static [&'static str]),")
    w("}")
    w("")
    w("/// A slot of a `<default>` class: the row that element kinds with a `class` read from.")
    w("#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]")
    w("pub enum DefaultSlot {")
    for s in SLOTS:
        w(f"    /// The `<{s}>` row of a default class.")
        w(f"    {camel(s)},")
    w("}")
    w("")
    w("/// One element kind: the schema's element, with the XML tag it is written with.")
    w("#[derive(Debug)]")
    w("pub struct ElementSpec {")
    w('    /// Schema name, unique (e.g. `"equality_joint"`, `"spatial_geom"`, `"body"`).')
    w('    pub name: &\'static str,')
    w('    /// XML tag (e.g. `"joint"`, `"geom"`).')
    w("    pub tag: &'static str,")
    w("    /// The attributes, in the schema's declaration order.")
    w("    pub attrs: &'static [AttrSpec],")
    w("    /// Schema names of the child kinds allowed.")
    w("    pub children: &'static [&'static str],")
    w("    /// The `<default>` slot that applies to it (via `class`/`childclass`); for a default row")
    w("    /// (`default_geom`, `default_motor`, ...), the slot that row sets.")
    w("    pub default_slot: Option<DefaultSlot>,")
    w("}")
    w("")
    w("impl ElementSpec {")
    w("    /// The attribute `name` of this kind, if it has one.")
    w("    pub fn attr(&self, name: &str) -> Option<&'static AttrSpec> {")
    w("        self.attrs.iter().find(|a| a.name == name)")
    w("    }")
    w("}")
    w("")
    w("/// All element kinds, sorted by name.")
    w("pub fn elements() -> &'static [ElementSpec] {")
    w("    ELEMENTS")
    w("}")
    w("")
    w("/// The element kind with schema name `name`.")
    w("pub fn element(name: &str) -> Option<&'static ElementSpec> {")
    w("    ELEMENTS")
    w("        .binary_search_by(|e| e.name.cmp(name))")
    w("        .ok()")
    w("        .map(|i| &ELEMENTS[i])")
    w("}")
    w("")
    w("/// The document root kind, `mujoco`.")
    w("pub fn root() -> &'static ElementSpec {")
    w(f"    &ELEMENTS[{index['mujoco']}]")
    w("}")
    w("")
    w("/// The kind of a child element with `tag` inside `parent`, resolving context: a `<joint>`")
    w("/// in `<equality>` is `equality_joint`, in `<body>` `joint`, in `<fixed>` `fixed_joint`, in")
    w("/// `<composite>` `composite_joint`; `worldbody`, `frame` and `replicate` take body's")
    w("/// children; the children of `<default>` are default rows (`default_geom`, ...).")
    w("pub fn child(parent: &ElementSpec, tag: &str) -> Option<&'static ElementSpec> {")
    w("    parent")
    w("        .children")
    w("        .iter()")
    w("        .filter_map(|name| element(name))")
    w("        .find(|e| e.tag == tag)")
    w("}")
    w("")
    params = shortcut_params(b)
    w("/// For the actuator shortcuts (`motor`, `position`, `velocity`, ...): the attributes that are")
    w("/// shortcut parameters (`kp`, `kv`, `timeconst`, muscle's `range`, ...) rather than")
    w("/// mechanical attributes read straight into the actuator, i.e. those `<general>` lacks, plus")
    w("/// `inheritrange`. Empty for `general` and for any other tag.")
    w("pub fn shortcut_params(tag: &str) -> &'static [&'static str] {")
    w("    match tag {")
    for tag, ps in params.items():
        if ps:
            quoted = ", ".join(f'"{p}"' for p in ps)
            w(f'        "{tag}" => &[{quoted}],')
    w("        _ => &[],")
    w("    }")
    w("}")
    w("")
    w("use AttrKind::{File, Id, ObjName, ObjType, Plain, Ref, RefList};")
    w("use Value::{Ints, Keyword, Reals, Text};")
    w("")
    w("const fn a(name: &'static str, kind: AttrKind, value: Value) -> AttrSpec {")
    w("    AttrSpec {")
    w("        name,")
    w("        kind,")
    w("        nodefault: false,")
    w("        value,")
    w("    }")
    w("}")
    w("")
    w("const fn nd(name: &'static str, kind: AttrKind, value: Value) -> AttrSpec {")
    w("    AttrSpec {")
    w("        name,")
    w("        kind,")
    w("        nodefault: true,")
    w("        value,")
    w("    }")
    w("}")
    w("")
    used = sorted({x.value.split(":")[1] for e in els for x in e.attrs
                   if x.value.startswith("Keyword:")})
    for name in used:
        keys = ["false", "true"] if name == "bool" else ENUMS[name]
        what = "`bool`" if name == "bool" else f"`enum<{name}>`"
        quoted = ", ".join('"' + k + '"' for k in keys)
        w(f"/// The keywords of {what}.")
        w(f"const KW_{name.upper()}: &[&str] = &[{quoted}];")
    w("")
    # Attribute rows, shared between kinds whose rows are identical.
    row_const: dict[tuple, str] = {}
    for e in els:
        if not e.attrs:
            continue
        key = tuple((x.name, x.kind, x.nodefault, x.comment, x.value) for x in e.attrs)
        if key in row_const:
            continue
        cname = f"{e.name.upper()}_ATTRS"
        row_const[key] = cname
        users = [x.name for x in els if tuple(
            (y.name, y.kind, y.nodefault, y.comment, y.value) for y in x.attrs) == key]
        doc = f"Attributes of {', '.join(f'`{u}`' for u in users)}."
        for piece in textwrap.wrap(doc, 94):
            w(f"/// {piece}")
        w(f"const {cname}: &[AttrSpec] = &[")
        for x in e.attrs:
            # Uses the imported variant names (the `use AttrKind::...` above).
            fn = "nd" if x.nodefault else "a"
            line = f'    {fn}("{x.name}", {rust_kind(x.kind)}, {rust_value(x.value)}),'
            if x.comment:
                line += f" // {x.comment}"
            w(line)
        w("];")
        w("")
    w("static ELEMENTS: &[ElementSpec] = &[")
    for e in els:
        key = tuple((x.name, x.kind, x.nodefault, x.comment, x.value) for x in e.attrs)
        attrs = row_const.get(key, "&[]")
        kids = ", ".join(f'"{c}"' for c in e.children)
        slot = f"Some(DefaultSlot::{camel(e.slot)})" if e.slot else "None"
        w("    ElementSpec {")
        w(f'        name: "{e.name}",')
        w(f'        tag: "{e.tag}",')
        w(f"        attrs: {attrs},")
        w(f"        children: &[{kids}],")
        w(f"        default_slot: {slot},")
        w("    },")
    w("];")
    w("")
    w(TESTS)
    return "\n".join(o) + "\n"


TESTS = r'''#[cfg(test)]
mod tests {
    use super::*;

    fn el(name: &str) -> &'static ElementSpec {
        element(name).unwrap_or_else(|| panic!("no element {name}"))
    }

    #[test]
    fn table_is_sorted_and_children_resolve() {
        assert!(ELEMENTS.windows(2).all(|w| w[0].name < w[1].name));
        for e in ELEMENTS {
            for c in e.children {
                assert!(element(c).is_some(), "{}: unknown child {c}", e.name);
            }
            let tags: Vec<_> = e.children.iter().map(|c| el(c).tag).collect();
            for (i, t) in tags.iter().enumerate() {
                assert!(!tags[..i].contains(t), "{}: two children with tag {t}", e.name);
            }
            for (i, at) in e.attrs.iter().enumerate() {
                assert!(e.attrs[..i].iter().all(|b| b.name != at.name), "{}.{}", e.name, at.name);
            }
        }
        assert_eq!(root().name, "mujoco");
        assert!(element("include").is_none());
    }

    #[test]
    fn weld_sites_are_site_refs() {
        let weld = el("weld");
        assert_eq!(weld.attr("site1").unwrap().kind, AttrKind::Ref(Ns::Site));
        assert_eq!(weld.attr("site2").unwrap().kind, AttrKind::Ref(Ns::Site));
        assert_eq!(weld.attr("name").unwrap().kind, AttrKind::Id(Ns::Equality));
    }

    #[test]
    fn spatial_geom_has_no_name() {
        let g = child(el("spatial"), "geom").unwrap();
        assert_eq!(g.name, "spatial_geom");
        assert!(g.attr("name").is_none());
        assert_eq!(g.attr("geom").unwrap().kind, AttrKind::Ref(Ns::Geom));
        assert_eq!(child(el("body"), "geom").unwrap().name, "geom");
    }

    #[test]
    fn texture_has_seven_files() {
        let n = el("texture")
            .attrs
            .iter()
            .filter(|a| a.kind == AttrKind::File)
            .count();
        assert_eq!(n, 7);
    }

    #[test]
    fn joint_by_context() {
        assert_eq!(child(el("equality"), "joint").unwrap().name, "equality_joint");
        assert_eq!(child(el("body"), "joint").unwrap().name, "joint");
        assert_eq!(child(el("fixed"), "joint").unwrap().name, "fixed_joint");
        assert_eq!(child(el("composite"), "joint").unwrap().name, "composite_joint");
        for alias in ["worldbody", "frame", "replicate"] {
            assert_eq!(child(el(alias), "body").unwrap().name, "body");
            assert_eq!(child(el(alias), "frame").unwrap().name, "frame");
        }
        assert_eq!(child(root(), "worldbody").unwrap().name, "worldbody");
        assert!(child(root(), "body").is_none());
    }

    #[test]
    fn default_rows() {
        let d = el("default");
        assert_eq!(d.attr("class").unwrap().kind, AttrKind::Id(Ns::Default));
        assert_eq!(child(d, "default").unwrap().name, "default");
        let g = child(d, "geom").unwrap();
        assert_eq!(g.name, "default_geom");
        assert_eq!(g.default_slot, Some(DefaultSlot::Geom));
        assert_eq!(child(d, "motor").unwrap().default_slot, Some(DefaultSlot::Actuator));
        for e in ELEMENTS.iter().filter(|e| e.name.starts_with("default_")) {
            assert!(e.attr("name").is_none() && e.attr("class").is_none(), "{}", e.name);
            assert!(e.attrs.iter().all(|a| !a.nodefault), "{}", e.name);
        }
        assert!(el("camera").attr("target").unwrap().nodefault);
        assert!(el("default_camera").attr("target").is_none());
        assert_eq!(el("geom").attr("class").unwrap().kind, AttrKind::Ref(Ns::Default));
        assert_eq!(el("body").attr("childclass").unwrap().kind, AttrKind::Ref(Ns::Default));
    }

    #[test]
    fn default_slots() {
        assert_eq!(el("motor").default_slot, Some(DefaultSlot::Actuator));
        assert_eq!(el("actuator_plugin").default_slot, Some(DefaultSlot::Actuator));
        assert_eq!(el("equality_joint").default_slot, Some(DefaultSlot::Equality));
        assert_eq!(el("spatial").default_slot, Some(DefaultSlot::Tendon));
        assert_eq!(el("geom").default_slot, Some(DefaultSlot::Geom));
        assert_eq!(el("body").default_slot, None);
        assert_eq!(el("composite_geom").default_slot, None);
    }

    #[test]
    fn shortcuts() {
        assert!(shortcut_params("position").contains(&"kp"));
        assert!(shortcut_params("muscle").contains(&"range"));
        assert!(shortcut_params("cylinder").contains(&"area"));
        assert!(!shortcut_params("position").contains(&"gear"));
        assert!(shortcut_params("general").is_empty());
        assert!(shortcut_params("motor").is_empty());
    }

    #[test]
    fn names_and_polymorphic_refs() {
        assert_eq!(el("key").attr("name").unwrap().kind, AttrKind::Id(Ns::Key));
        assert_eq!(el("flex").attr("body").unwrap().kind, AttrKind::RefList(Ns::Body));
        assert_eq!(el("flex").attr("node").unwrap().kind, AttrKind::RefList(Ns::Body));
        let fp = el("framepos");
        assert_eq!(
            fp.attr("objtype").unwrap().kind,
            AttrKind::ObjType { name_attr: "objname" }
        );
        assert_eq!(fp.attr("refname").unwrap().kind, AttrKind::ObjName);
        assert_eq!(el("element").attr("objname").unwrap().kind, AttrKind::ObjName);
        let at = el("attach");
        assert_eq!(at.attr("model").unwrap().kind, AttrKind::Ref(Ns::Model));
        assert_eq!(at.attr("body").unwrap().kind, AttrKind::Ref(Ns::Body));
        assert_eq!(at.attr("prefix").unwrap().kind, AttrKind::Plain);
        assert_eq!(el("model").attr("file").unwrap().kind, AttrKind::File);
        assert_eq!(Ns::Hfield.as_str(), "hfield");
    }
}'''


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--schema", required=True, type=Path, help="local copy of mjcf.schema")
    ap.add_argument("--schema-rev", default="", help="mujoco commit the schema copy is from")
    ap.add_argument("--python", default=sys.executable,
                    help=f"a Python with mujoco=={PINNED_MUJOCO} (default: this one)")
    ap.add_argument("--out", type=Path,
                    default=Path(__file__).resolve().parent.parent / "src" / "document" / "vocab.rs")
    ap.add_argument("--no-rustfmt", action="store_true")
    args = ap.parse_args()

    schema_bytes = args.schema.read_bytes()
    schema, ns_set = parse_schema(schema_bytes.decode("utf-8"))
    version, tree_text = run_print_schema(args.python)
    check_symbolic_counts(args.python)
    if version != PINNED_MUJOCO:
        die(f"{args.python} has mujoco {version}, expected {PINNED_MUJOCO}")
    tree = parse_print_schema(tree_text)
    b = build(schema, tree)

    namespaces = [n for n in NS_ORDER if n in ns_set] + sorted(ns_set - set(NS_ORDER))
    for e in b.out.values():
        for x in e.attrs:
            head, _, arg = x.kind.partition(":")
            if head in ("Id", "Ref", "RefList") and arg not in namespaces:
                die(f"{e.name}.{x.name}: namespace {arg} unknown")

    text = emit(b, namespaces, args, hashlib.sha256(schema_bytes).hexdigest())
    args.out.write_text(text)
    if not args.no_rustfmt:
        rustfmt = shutil.which("rustfmt")
        if rustfmt:
            subprocess.run([rustfmt, "--edition", "2024", str(args.out)], check=True)
        else:
            warn("rustfmt not found: output left unformatted")

    for line in report(b, schema, tree_text):
        warn(line)
    counts: dict[str, int] = {}
    for e in b.out.values():
        for x in e.attrs:
            h = x.kind.partition(":")[0]
            counts[h] = counts.get(h, 0) + 1
    warn(f"wrote {args.out}: {len(b.out)} elements, "
         f"{sum(len(e.attrs) for e in b.out.values())} attribute rows, {counts}")


if __name__ == "__main__":
    main()
