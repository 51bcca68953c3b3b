"""The package as users meet it: stubs that match the module, docstrings on everything
public, ``help()`` that reads well, one exception type."""
from __future__ import annotations

import ast
import inspect
import pydoc
from pathlib import Path

import mjcf_forge
from helpers import ROOT

STUB = Path(mjcf_forge.__file__).with_name("_mjcf_forge.pyi")
PUBLIC_CLASSES = ["Attrib", "Document", "Element", "MergeReport", "Model", "Scene", "Variant", "VariantIterator"]


def stub_members() -> dict[str, set[str]]:
    tree = ast.parse(STUB.read_text())
    out: dict[str, set[str]] = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            out[node.name] = {
                n.name if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) else n.target.id
                for n in node.body
                if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.AnnAssign))
            }
    return out


def runtime_members(cls) -> set[str]:
    return {
        name
        for name in vars(cls)
        if not name.startswith("_") or name in {"__init__", "__next__", "__iter__"}
    }


def test_installed_package_has_stubs_and_py_typed():
    assert STUB.is_file()
    assert Path(mjcf_forge.__file__).with_name("py.typed").is_file()
    assert set(mjcf_forge.__all__) >= set(PUBLIC_CLASSES) | {"MjcfError"}


def test_stubs_name_exactly_the_public_methods_and_properties():
    stubs = stub_members()
    for name in PUBLIC_CLASSES:
        cls = getattr(mjcf_forge, name)
        in_stub = {m for m in stubs[name] if not m.startswith("_") or m in {"__next__", "__iter__"}}
        at_runtime = {m for m in runtime_members(cls) if m != "__init__"}
        assert at_runtime == in_stub, (name, at_runtime ^ in_stub)
    assert "errors" in stubs["MjcfError"]


def test_stubs_type_the_internal_entry_points_too():
    """What the package's own modules call on the extension is typed in the stub as it is:
    every module-level name, every class's methods and fields (underscored ones included),
    and the named result of ``Document._split()``."""
    from mjcf_forge import _mjcf_forge

    tree = ast.parse(STUB.read_text())
    top = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            top.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            top.add(node.target.id)
    runtime = set(vars(_mjcf_forge))
    assert top - runtime == set(), top - runtime
    stubs = stub_members()
    for node in tree.body:
        if not isinstance(node, ast.ClassDef):
            continue
        cls = getattr(_mjcf_forge, node.name)
        private = {m for m in vars(cls) if m.startswith("_") and not m.startswith("__")}
        assert private <= stubs[node.name], (node.name, private - stubs[node.name])
        methods = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        assert {m for m in methods if not hasattr(cls, m)} == set(), node.name
    split = mjcf_forge.Document.from_string(
        "<mujoco><worldbody><geom size='.1' rgba='1 0 0 1'/></worldbody></mujoco>"
    )._split()
    assert isinstance(split, _mjcf_forge.DocumentSplit)
    for field in stubs["DocumentSplit"]:
        assert hasattr(split, field), field
    assert isinstance(split.numbers, bytes) and len(split.numbers) % 8 == 0
    import mujoco

    # The tables against MuJoCo's own: mjtJoint's numbers, mjStatistic's fields.
    assert _mjcf_forge.JOINT_TYPES == tuple(mujoco.mjtJoint(i).name[6:].lower() for i in range(4))
    stat = mujoco.MjModel.from_xml_string("<mujoco/>").stat
    assert set(_mjcf_forge.STATISTIC_NAMES) == {n for n in dir(stat) if not n.startswith("_")}


def test_every_public_member_has_a_docstring():
    missing = []
    for name in PUBLIC_CLASSES:
        cls = getattr(mjcf_forge, name)
        if not (cls.__doc__ or "").strip():
            missing.append(name)
        for member in runtime_members(cls):
            if member.startswith("_"):
                continue
            doc = inspect.getdoc(getattr(cls, member))
            if not doc or not doc.strip():
                missing.append(f"{name}.{member}")
    assert not missing, missing
    assert "file:line:col" in mjcf_forge.MjcfError.__doc__


def test_help_of_scene_reads_well():
    text = pydoc.render_doc(mjcf_forge.Scene, renderer=pydoc.plaintext)
    for expected in ["variant(self, /, index)", "variants(self, /, indices, threads=None, window=None, progress=None)",
                     "from_dict(description, base_dir=None)", "(seed, i)", "GIL"]:
        assert expected in text, expected


def test_help_shows_real_defaults():
    # A Rust-side default that Python cannot show appears as "Ellipsis" in help().
    for name in PUBLIC_CLASSES:
        text = pydoc.render_doc(getattr(mjcf_forge, name), renderer=pydoc.plaintext)
        assert "Ellipsis" not in text, name
    assert "contact_geom_rgba=(0.0, 0.5, 0.0, 1.0)" in pydoc.render_doc(mjcf_forge.Model)


def test_one_exception_type_derives_from_value_error():
    assert issubclass(mjcf_forge.MjcfError, ValueError)
    assert mjcf_forge.MjcfError.__module__ == "mjcf_forge"


def test_a_rust_panic_reaches_python_as_mjcf_error():
    import pytest

    from mjcf_forge._mjcf_forge import _testing

    for detached in (True, False):
        with pytest.raises(mjcf_forge.MjcfError) as err:
            _testing.panic(detached=detached)
        assert err.value.errors == [
            "internal error in mjcf-forge (please report it): deliberate panic for the tests"
        ]
    # The module still works afterwards.
    assert mjcf_forge.Document.from_string("<mujoco/>").to_xml() == "<mujoco/>"


def test_the_compiled_modules_examples_run():
    """Every ``>>>`` example in a docstring of the compiled module (its functions and
    classes, with their methods) runs and prints what it says."""
    import doctest

    from mjcf_forge import _mjcf_forge

    finder, runner = doctest.DocTestFinder(exclude_empty=True), doctest.DocTestRunner()
    examples = 0
    # The module's own names and its submodule _testing's (the tests' entry points).
    members = [(name, getattr(_mjcf_forge, name)) for name in dir(_mjcf_forge)]
    members += [(f"_testing.{n}", getattr(_mjcf_forge._testing, n)) for n in dir(_mjcf_forge._testing)]
    for name, obj in members:
        if name.split(".")[-1].startswith("__") or not (inspect.isclass(obj) or callable(obj)):
            continue
        for test in finder.find(obj, name, globs={}):
            examples += len(test.examples)
            runner.run(test)
    assert runner.failures == 0, f"{runner.failures} of {examples} examples failed"
    assert examples >= 14, examples


def test_the_python_modules_examples_run(monkeypatch):
    """Every ``>>>`` example in the docstrings of the package's Python modules runs and
    prints what it says (paths in them are relative to the repository's root)."""
    import doctest
    import importlib
    import pkgutil

    monkeypatch.chdir(ROOT)
    finder, runner = doctest.DocTestFinder(exclude_empty=True), doctest.DocTestRunner()
    examples, modules = 0, 0
    names = ["mjcf_forge"] + [i.name for i in pkgutil.iter_modules(mjcf_forge.__path__, "mjcf_forge.")]
    for name in names:
        module = importlib.import_module(name)
        if not getattr(module, "__file__", "").endswith(".py"):
            continue
        modules += 1
        for test in finder.find(module, name):
            examples += len(test.examples)
            runner.run(test)
    assert runner.failures == 0, f"{runner.failures} of {examples} examples failed"
    assert modules >= 20 and examples >= 10, (modules, examples)
