"""pytest: the compiled core under numpy 1 (Debian's python3) and numpy 2 (make test's
pytest_numpy2 run, a PyPI venv): built with pybind11 >= 2.12 it exchanges arrays with both; the
import refuses only a core built with an older pybind11 under numpy 2."""

from __future__ import annotations

import os

import numpy as np
import pytest

import downstream_perception as dp


def test_running_under_the_numpy_asked_for() -> None:
    if os.environ.get("DP_NUMPY2_MISSING") == "1":
        pytest.skip("no numpy 2 venv (PyPI unreachable when make deps ran)")
    major = int(np.__version__.split(".")[0])
    if os.environ.get("DP_EXPECT_NUMPY2") == "1":
        assert major >= 2, np.__version__
    # Built with PyPI's pybind11 by make build (Debian's 2.10 only when PyPI was unreachable).
    version = tuple(dp._core.pybind11_version)
    assert major < 2 or version >= (2, 12), version


def test_arrays_cross_the_binding_row_by_row() -> None:
    # The numpy 2 failure of pybind11 < 2.12 was silent: every row a copy of the first. One
    # lethal cell in the second row must come back inflated around that row only.
    costs = np.zeros((5, 7), dtype=np.uint8)
    costs[1, 5] = dp.LETHAL_OBSTACLE
    config = dp.InflationConfig()
    config.inflation_radius = 0.0  # lethal and inscribed only: no decay to reason about
    out = dp.inflate(costs, 1.0, config)
    assert out.shape == (5, 7) and out.dtype == np.uint8
    assert out[1, 5] == dp.LETHAL_OBSTACLE
    assert (out[0] != out[1]).any() or (out[3] != out[1]).any()
    assert (out[3:] == dp.FREE_SPACE).all()


def test_the_refusal_names_the_fix() -> None:
    assert dp.numpy_abi_problem("1.24.2", (2, 10)) is None
    assert dp.numpy_abi_problem("2.1.0", (2, 13)) is None
    problem = dp.numpy_abi_problem("2.1.0", (2, 10))
    assert problem is not None and "pybind11 >= 2.12" in problem
