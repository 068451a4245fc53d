"""The module's public names: each documented (help() shows it) and typed in insitu.pyi."""
import ast
import inspect
import os

import insitu


def public(names):
    return {name for name in names if not name.startswith("_")}


def stub():
    """Top-level names of insitu.pyi and, per class, its members."""
    path = os.path.join(os.path.dirname(insitu.__file__), "insitu.pyi")
    with open(path) as f:
        tree = ast.parse(f.read())
    names, members = set(), {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names.add(node.name)
            members[node.name] = public(
                n.name if isinstance(n, ast.FunctionDef) else n.target.id
                for n in node.body if isinstance(n, (ast.FunctionDef, ast.AnnAssign)))
            members[node.name] |= {t.id for n in node.body if isinstance(n, ast.Assign)
                                   for t in n.targets}
        elif isinstance(node, ast.FunctionDef):
            names.add(node.name)
    return public(names), members


def module_names():
    return {name for name in public(dir(insitu)) if not inspect.ismodule(getattr(insitu, name))}


def test_every_public_name_has_a_docstring():
    undocumented = []
    for name in module_names():
        value = getattr(insitu, name)
        if not (value.__doc__ or "").strip():
            undocumented.append(name)
        if inspect.isclass(value) and not issubclass(value, BaseException):
            for member, attribute in vars(value).items():
                if member.startswith("_") or member in ("name", "value"):
                    continue
                if not (getattr(attribute, "__doc__", "") or "").strip():
                    undocumented.append(f"{name}.{member}")
    assert undocumented == []


def test_the_stub_names_what_the_module_has():
    names, members = stub()
    assert names == module_names()
    for name, listed in members.items():
        value = getattr(insitu, name)
        if issubclass(value, BaseException):
            continue
        has = public(vars(value)) - {"name", "value"}
        assert listed == has, name
