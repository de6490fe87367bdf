"""The type stubs (_native.pyi) describe the native module as built, and everything public has
a docstring."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import bondmech
from bondmech import _native


def stub_tree():
    path = Path(bondmech.__file__).with_name("_native.pyi")
    assert path.is_file(), "the stubs are installed with the package"
    return ast.parse(path.read_text())


def test_stubs_name_every_native_class_function_and_method():
    tree = stub_tree()
    stubbed = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            stubbed[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        elif isinstance(node, ast.FunctionDef):
            stubbed[node.name] = None
    for name in dir(_native):
        if name.startswith("__") or name.isupper():
            continue
        obj = getattr(_native, name)
        if inspect.ismodule(obj):
            continue
        assert name in stubbed, f"{name} is missing from _native.pyi"
        if inspect.isclass(obj):
            methods = {m for m in vars(obj) if not m.startswith("__") and m != "_from_parts"}
            missing = methods - stubbed[name]
            assert not missing, f"{name}: {sorted(missing)} missing from _native.pyi"


def test_public_api_has_docstrings():
    for name in bondmech.__all__:
        obj = getattr(bondmech, name)
        if callable(obj):
            assert (obj.__doc__ or "").strip(), f"bondmech.{name} has no docstring"
    for cls in (bondmech.Scene, bondmech.Solution, bondmech.Mechanism, bondmech.PlanarBody):
        for m, f in vars(cls).items():
            if not m.startswith("_") and callable(f):
                assert (f.__doc__ or "").strip(), f"{cls.__name__}.{m} has no docstring"


def test_the_extension_is_one_abi3_module_on_sundials_6():
    # abi3 (the stable ABI): one wheel serves every CPython >= 3.9
    assert _native.__file__.endswith(".abi3.so"), _native.__file__
    assert bondmech.SUNDIALS_VERSION[0] == 6
