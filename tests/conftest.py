"""Shared fixtures: the built FMUs (built once per session if missing or stale)."""
from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def fmu_dir() -> Path:
    """fmus/ of the checkout, with every model built and validated."""
    from marinefmu.cosim.build import build_all

    build_all(verbose=False)
    return ROOT / "fmus"


@pytest.fixture(scope="session")
def relay_fmu(tmp_path_factory) -> Path:
    """A test-only FMU with inputs (tests/models/MfTestRelay.py), to exercise wiring and rates."""
    from marinefmu.cosim.build import build_all

    dest = tmp_path_factory.mktemp("relay")
    build_all(models=ROOT / "tests" / "models", dest=dest, verbose=False)
    return dest / "MfTestRelay.fmu"
