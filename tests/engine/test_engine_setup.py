"""Tolerance semantics of the step rule, and the start-up of a fresh interpreter."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np

import grazing
from grazing.engine.codegen import taylor_order
from grazing.engine.runner import step_safety
from grazing.models import pendulum


def test_error_follows_the_tolerance():
    """The step h = rho tol^(1/(order+1)) makes the error of a run proportional to tol.

    On a nonimpacting (contracting) orbit the samples of a run at tolerance
    1e-10 stay within a few tol of a run at machine precision: a step rule
    that overshot the tolerance would be caught, and so would one far more
    cautious than it needs (Jorba & Zou's h = rho e^-2 gives 3.7e-13 here).
    """
    m = pendulum("B", eta=0.3, theta_hat=math.radians(40))  # stop out of reach
    exact = grazing.simulate(m, [0.0, 0.0], periods=300)
    loose = grazing.simulate(m, [0.0, 0.0], periods=300, tol=1e-10)
    assert exact.n_impacts == loose.n_impacts == 0
    dev = np.abs(exact.samples - loose.samples).max()
    assert 1e-12 < dev < 20 * 1e-10


def test_step_safety_sets_the_truncation_error_to_the_tolerance():
    for tol in (1e-6, 1e-10, 2.220446049250313e-16):
        p = taylor_order(tol)
        c = step_safety(tol, p)
        assert math.isclose(math.exp(-c * (p + 1)), tol, rel_tol=1e-12)
        assert 1.0 < c < 2.0  # longer steps than Jorba & Zou's e^-2, never longer than rho / e


def test_fresh_interpreter_keeps_scipy_and_numba_linear_algebra_usable():
    """Loading the kernels hides scipy.linalg from numba's BLAS probe only for that import."""
    code = (
        "import math, numpy as np, grazing\n"
        "m = grazing.models.pendulum('B', eta=0.446, theta_hat=math.radians(40))\n"
        "grazing.simulate(m, [0.0, 0.0], periods=2)\n"
        "import sys; assert sys.modules.get('scipy.linalg', 0) is not None\n"
        "import scipy.linalg\n"
        "from numba import njit\n"
        "a = np.array([[2.0, 1.0], [1.0, 3.0]])\n"
        "assert abs(njit(lambda x: np.linalg.det(x))(a) - 5.0) < 1e-12\n"
        "assert abs(scipy.linalg.det(a) - 5.0) < 1e-12\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"
