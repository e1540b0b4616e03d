"""The examples in the estimators' docstrings run and print what they say (doctest), so that the
API reference, which shows them, cannot drift from the code."""
from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import marinefmu.estimators

FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
MODULES = sorted(m.name for m in pkgutil.walk_packages(marinefmu.estimators.__path__, "marinefmu.estimators."))
# the modules whose docstrings hold at least one example
WITH_EXAMPLES = [name for name in MODULES
                 if any(t.examples for t in doctest.DocTestFinder().find(importlib.import_module(name)))]


def test_the_estimators_show_examples():
    assert "marinefmu.estimators.heave.observer" in WITH_EXAMPLES and len(WITH_EXAMPLES) >= 8


@pytest.mark.parametrize("name", WITH_EXAMPLES)
def test_docstring_examples_hold(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=FLAGS)
    assert result.attempted > 0 and result.failed == 0, f"{result.failed} of {result.attempted} fail in {name}"
