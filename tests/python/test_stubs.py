"""The type stubs (l6470emu/_l6470emu.pyi) match the extension: the same public names at
module level and the same public members in every class, so the stubs cannot drift."""
import ast
import inspect
from pathlib import Path

import l6470emu
from l6470emu import _l6470emu

STUBS = Path(l6470emu.__file__).with_name("_l6470emu.pyi")


def stub_tree():
    return ast.parse(STUBS.read_text())


def public(names):
    return {n for n in names if not n.startswith("_") or n in ("__version__",)}


def test_the_stub_names_every_module_level_name_and_no_other():
    names = set()
    for node in stub_tree().body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
    assert public(names) == public(dir(_l6470emu)) - {"annotations"}


def test_every_class_in_the_stub_has_the_members_of_the_real_one():
    for node in stub_tree().body:
        if not isinstance(node, ast.ClassDef):
            continue
        real = getattr(_l6470emu, node.name)
        stub_members = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        stub_members |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        if issubclass(real, BaseException):
            continue  # file/line are set on instances
        real_members = {n for n in dir(real) if not n.startswith("_")}
        if hasattr(real, "__members__"):  # enums: their values, plus name/value
            real_members = set(real.__members__) | ({"name", "value"} & stub_members)
        dunder = {n for n in stub_members if n.startswith("__")}
        assert public(stub_members) == real_members, node.name
        for d in dunder:
            assert hasattr(real, d), f"{node.name}.{d}"


def test_every_public_function_and_method_has_a_docstring():
    missing = []
    for name in public(dir(_l6470emu)):
        obj = getattr(_l6470emu, name)
        if inspect.isclass(obj):
            if not obj.__doc__:
                missing.append(name)
            for member, value in vars(obj).items():
                if member.startswith("_") or hasattr(obj, "__members__"):
                    continue
                if not (getattr(value, "__doc__", None) or "").strip() or (value.__doc__ or "").startswith("(self"):
                    missing.append(f"{name}.{member}")
        elif callable(obj) and not (obj.__doc__ or "").strip():
            missing.append(name)
    assert not missing
