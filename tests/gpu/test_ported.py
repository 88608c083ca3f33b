"""The text :mod:`grazing.gpu.ported` compiles for the device, checked on the CPU (no simulator needed).

A module's array read by a device function is copied into the device's 64 kB bank of constants once per
signature: ``polyroots._QUOTIENTS`` twice made every sweep kernel fail to assemble ("too much global
constant data", ``ptxas`` for sm_90).  The ported text computes the quotients where it reads them; these
tests keep it so, and check that what it computes is the CPU's to the bit.
"""

from __future__ import annotations

import ast
import importlib
import math

import numpy as np
import pytest

import grazing.engine.polyroots as polyroots
from grazing.gpu.ported import PORTED, _constants, _function_text


def _arrays(module: object) -> set[str]:
    return {k for k, v in vars(module).items() if isinstance(v, np.ndarray)}


@pytest.mark.parametrize("modname", list(PORTED))
def test_no_ported_function_reads_an_array_of_its_module(modname: str) -> None:
    module = importlib.import_module(modname)
    arrays = _arrays(module)
    assert not arrays & set(_constants(module))
    for name in PORTED[modname]:
        names = {n.id for n in ast.walk(ast.parse(_function_text(module, name))) if isinstance(n, ast.Name)}
        assert not names & arrays, f"{modname}.{name} reads the array {names & arrays}"


def test_the_ported_bernstein_conversion_equals_the_cpus_to_the_bit() -> None:
    namespace: dict[str, object] = {"math": math, **_constants(polyroots)}
    exec(_function_text(polyroots, "to_bernstein"), namespace)
    ported = namespace["to_bernstein"]
    rng = np.random.default_rng(46)
    for n in (0, 1, 2, 7, 19, 33, 64):
        a = rng.standard_normal(n + 1) * 10.0 ** rng.integers(-8, 8, n + 1)
        want, got = np.zeros(n + 1), np.zeros(n + 1)
        polyroots.to_bernstein(a, n, want)
        ported(a, n, got)  # type: ignore[operator]
        assert got.tobytes() == want.tobytes(), n
