"""Every public callable of the flexmbd package has a docstring.

Public: the names of flexmbd, flexmbd.study and flexmbd._flexmbd not starting with "_",
the public methods of their classes and the properties (pybind11 attributes) of the
classes. A pybind11 function's docstring always holds its signature; only text beyond
the signature lines counts. The reference built from them: make apidocs.
"""
import inspect
import re

import flexmbd
import flexmbd._flexmbd as _ext
import flexmbd.study

def _text(doc, name):
    """The docstring without pybind11's signature lines ("name(arg: type) -> ret",
    "Overloaded function.", "1. name(...)"): empty if nothing else."""
    if not doc:
        return ""
    signature = re.compile(r"^(\d+\. )?" + re.escape(name) + r"\(.*\)( -> .*)?$")
    lines = [line.strip() for line in doc.splitlines()]
    return " ".join(line for line in lines
                    if line and line != "Overloaded function." and not signature.match(line))


def _own_doc(obj):
    """obj's own docstring (a class's, not one inherited from its bases)."""
    doc = getattr(obj, "__doc__", None)
    if inspect.isclass(obj) and any(doc is getattr(base, "__doc__", None) for base in obj.__mro__[1:]):
        return None
    return doc if isinstance(doc, str) else None


def _public(module):
    for name in sorted(dir(module)):
        if name.startswith("_"):
            continue
        obj = getattr(module, name)
        if inspect.ismodule(obj) or not callable(obj):
            continue
        # what the module defines or re-exports from the package (not typing, numpy, ...)
        owner = getattr(obj, "__module__", "") or ""
        if not (owner == "flexmbd" or owner.startswith("flexmbd.")):
            continue
        yield name, obj


def _undocumented():
    missing = []
    for module in (flexmbd, flexmbd.study, _ext):
        for name, obj in _public(module):
            full = f"{module.__name__}.{name}"
            if not _text(_own_doc(obj), name):
                missing.append(full)
            if not inspect.isclass(obj):
                continue
            # pybind11 enums: their "name" and "value" are pybind11's own (undocumented)
            builtin = {"name", "value"} if hasattr(obj, "__members__") else set()
            for member, value in vars(obj).items():
                if member.startswith("_") or member in builtin:
                    continue
                if isinstance(value, property) or callable(value) or hasattr(value, "__get__"):
                    doc = value.__doc__ if isinstance(value, (property, staticmethod, classmethod)) \
                        else getattr(value, "__doc__", None)
                    if isinstance(value, (staticmethod, classmethod)):
                        doc = value.__func__.__doc__
                    # enum values (pybind11 enum members) are instances, not callables
                    if isinstance(value, obj):
                        continue
                    if not _text(doc if isinstance(doc, str) else None, member):
                        missing.append(f"{full}.{member}")
    return sorted(set(missing))


def test_every_public_callable_has_a_docstring():
    missing = _undocumented()
    assert not missing, f"{len(missing)} public names without a docstring: " + ", ".join(missing)
