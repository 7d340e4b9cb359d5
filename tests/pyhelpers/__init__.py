"""Helpers that several Python test files use (fixtures are in conftest.py); ray_cluster: a
real Ray cluster on loopback (sweep.ray_cluster_parking, marl.ray_train)."""

from __future__ import annotations

from pathlib import Path
from typing import Callable

# The repository (tests/ is in it); the root fixture of conftest.py, for module-level constants.
REPO_ROOT = Path(__file__).resolve().parents[2]


def raises(fn: Callable[[], object], exc: type[BaseException], *texts: str) -> None:
    """fn() raises exc with every text in its message."""
    try:
        fn()
    except exc as e:
        assert all(t in str(e) for t in texts), e
        return
    raise AssertionError(f"no {exc.__name__}")


def almost_equal(first: float, second: float, places: int = 7) -> bool:
    """first and second agree to places decimals (unittest's assertAlmostEqual)."""
    return first == second or round(abs(second - first), places) == 0
