"""Every public function of gearshot.signal, gearshot.features and gearshot.transfer
carries a worked numpydoc ``Examples`` section (issue #21, item 7); CI runs them as
doctests (``.ci/run``)."""
import doctest
import importlib
import inspect
import pkgutil

import pytest

import gearshot.signal
import gearshot.transfer

# private modules (``_uff58``, ...) hold helpers of the public ones, not public functions
MODULES = sorted(
    [f"gearshot.signal.{m.name}" for m in pkgutil.iter_modules(gearshot.signal.__path__)
     if not m.name.startswith("_")]
    + [f"gearshot.transfer.{m.name}" for m in pkgutil.iter_modules(gearshot.transfer.__path__)
       if not m.name.startswith("_")]
    + ["gearshot.features", "gearshot.paper"])


def _public_functions(module):
    names = getattr(module, "__all__", [n for n in vars(module) if not n.startswith("_")])
    for name in names:
        obj = getattr(module, name)
        if inspect.isfunction(obj) and obj.__module__ == module.__name__:
            yield name, obj


@pytest.mark.parametrize("name", MODULES)
def test_every_public_function_has_a_worked_example(name):
    module = importlib.import_module(name)
    missing = []
    for fname, func in _public_functions(module):
        doc = inspect.getdoc(func) or ""
        examples = doctest.DocTestParser().get_examples(doc)
        if "Examples\n--------" not in doc or not examples:
            missing.append(fname)
    assert not missing, f"{name}: no worked Examples in {missing}"


def test_the_check_sees_the_functions():
    """The enumeration is not vacuous: it finds the functions it should."""
    found = {n for m in MODULES for n, _ in _public_functions(importlib.import_module(m))}
    assert {"difference_signal", "extract_features", "estimate_transfer_function",
            "read_frf", "angular_resample", "subtract_healthy"} <= found
    assert len(found) >= 40
