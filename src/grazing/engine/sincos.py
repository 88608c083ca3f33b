"""sin and cos as the compiled model code computes them: one algorithm for a scalar and for SIMD lanes.

The Taylor kernels need ``sin`` and ``cos`` of the same argument (a state,
the forcing phase ``omega t``) at every step.  The C library computes them one
double at a time: on the SIMD lanes of a sweep (:mod:`grazing.engine.llvmgen`)
LLVM would split every vector into one call per lane.  Here they are
computed by straight-line arithmetic that the translator of
:mod:`grazing.engine.llvmgen` turns into the same operations on a scalar or on
a vector of lanes (so a lane gives the scalar's bits), with no call on the
fast path:

1. **Range reduction** (Cody and Waite, as fdlibm's ``__ieee754_rem_pio2`` for
   medium arguments, with every round done unconditionally): ``n`` is
   ``x 2/pi`` rounded to an integer (adding and subtracting ``1.5 2^52``),
   and ``r = x - n pi/2`` is computed as a pair ``hi + lo`` with ``pi/2``
   split in four parts.  The first three (fdlibm's ``pio2_1``, ``pio2_2``,
   ``pio2_3``) have at most 32 significant bits, so for ``|n| <= 2^20`` their
   products with ``n`` are exact, and each subtraction's rounding error is
   recovered exactly (Dekker's Fast2Sum; where its ordering condition fails
   the subtraction itself is exact); these errors and the fourth part make
   ``lo``, computed beside the kernels' first steps rather than before them
   (``|lo|`` is below one ulp of ``hi``, or below ``2^-31 |hi|`` where
   ``|hi| < 1e-12``: the kernels' first-order correction for ``lo`` holds).
   No double with ``|x| <`` :data:`LIMIT` is closer to a multiple of
   ``pi/2`` than ``2^-72.6 |x|`` (an exact scan of every multiple:
   ``tests/engine/test_sincos.py``), and the error of ``hi + lo`` stays
   below ``2^-80 |r|``.
2. **Kernels** on ``[-pi/4, pi/4]``: fdlibm's minimax polynomials for
   ``sin`` (degree 13) and ``cos`` (degree 14) with the correction for the
   tail ``lo``, as FreeBSD's ``k_sin.c`` and ``k_cos.c`` (Bruce Evans'
   branch-free ``cos``).
3. **Quadrant**: ``n mod 4`` picks ``(sin, cos)`` among ``(S, C)``,
   ``(C, -S)``, ``(-S, -C)``, ``(-C, S)``, by comparisons and selections.

Plain multiplications and additions in a fixed order (no fused
multiply-add, no fast-math), so the results do not depend on the processor.
Outside ``|x| <`` :data:`LIMIT` (and for NaN and infinities) the C library's
``sin`` and ``cos`` are used instead, lane by lane.  The error is below one
ulp (``tests/engine/test_sincos.py`` checks it against mpmath; over 1.2
million random arguments it was at most 0.78 ulp, and 97% of the values
were correctly rounded, against 99.9% of the C library's).  ``sin(-0.0)``
is ``-0.0``.

:func:`sincos_fast` is both the definition and the reference: Python runs it
on floats (the same IEEE operations), and the translator of
:mod:`grazing.engine.llvmgen` compiles its text (with the constants of
:data:`CONSTANTS`).

Examples
--------
>>> import math
>>> s, c = sincos(1.0)
>>> abs(s - math.sin(1.0)) <= math.ulp(s) and abs(c - math.cos(1.0)) <= math.ulp(c)
True
>>> sincos(-0.0)
(-0.0, 1.0)
>>> sincos(1e300) == (math.sin(1e300), math.cos(1e300))  # beyond LIMIT: the C library
True
"""

from __future__ import annotations

import math

__all__ = ["CONSTANTS", "LIMIT", "cos", "sin", "sincos", "sincos_fast"]

LIMIT = 1048576.0
"""``2^20``: arguments with ``|x| < LIMIT`` take the fast path (then ``|n| < 2^20``, exact products)."""

TOINT = float.fromhex("0x1.8p52")  # x + 1.5 2^52 - 1.5 2^52 rounds x to an integer (|x| < 2^51)
INVPIO2 = float.fromhex("0x1.45f306dc9c883p-1")  # 2/pi (fdlibm's invpio2)
PIO2_1 = float.fromhex("0x1.921fb544p0")  # the first 31 bits of pi/2 (fdlibm's pio2_1: 0x3FF921FB 54400000)
PIO2_2 = float.fromhex("0x1.0b4611a6p-34")  # the next 32 bits (pio2_2: 0x3DD0B461 1A600000)
PIO2_3 = float.fromhex("0x1.3198a2ep-69")  # the next 28 bits (pio2_3: 0x3BA3198A 2E000000)
PIO2_3T = float.fromhex("0x1.b839a252049c1p-104")  # pi/2 - (PIO2_1 + PIO2_2 + PIO2_3), rounded (pio2_3t)
# sin(x) ~ x + S1 x^3 + ... + S6 x^13 on [-pi/4, pi/4] (fdlibm's __kernel_sin)
S1 = float.fromhex("-0x1.5555555555549p-3")
S2 = float.fromhex("0x1.111111110f8a6p-7")
S3 = float.fromhex("-0x1.a01a019c161d5p-13")
S4 = float.fromhex("0x1.71de357b1fe7dp-19")
S5 = float.fromhex("-0x1.ae5e68a2b9cebp-26")
S6 = float.fromhex("0x1.5d93a5acfd57cp-33")
# cos(x) ~ 1 - x^2/2 + C1 x^4 + ... + C6 x^14 on [-pi/4, pi/4] (fdlibm's __kernel_cos)
C1 = float.fromhex("0x1.555555555554cp-5")
C2 = float.fromhex("-0x1.6c16c16c15177p-10")
C3 = float.fromhex("0x1.a01a019cb159p-16")
C4 = float.fromhex("-0x1.27e4f809c52adp-22")
C5 = float.fromhex("0x1.1ee9ebdb4b1c4p-29")
C6 = float.fromhex("-0x1.8fae9be8838d4p-37")

CONSTANTS = {
    "TOINT": TOINT, "INVPIO2": INVPIO2, "PIO2_1": PIO2_1, "PIO2_2": PIO2_2, "PIO2_3": PIO2_3,
    "PIO2_3T": PIO2_3T, "S1": S1, "S2": S2, "S3": S3, "S4": S4, "S5": S5, "S6": S6, "C1": C1, "C2": C2,
    "C3": C3, "C4": C4, "C5": C5, "C6": C6,
}  # fmt: skip
"""The names :func:`sincos_fast` reads, with their values (the translator's environment)."""


def sincos_fast(x: float) -> tuple[float, float]:
    """``(sin x, cos x)`` for ``|x| <`` :data:`LIMIT` (straight-line code: see the module's docstring).

    Outside that range the result is meaningless (:func:`sincos` takes the
    C library's there).  The body is translated to LLVM IR as it stands: only
    assignments of arithmetic, comparisons, ``abs`` and conditional expressions.
    """
    # n = x 2/pi rounded; m = n - 4 round(n/4), in -2 .. 2, is n mod 4 (up to a multiple of 4)
    t = x * INVPIO2 + TOINT
    n = t - TOINT
    m = n - 4.0 * ((n * 0.25 + TOINT) - TOINT)
    # r = x - n pi/2 = hi + lo (lo, tiny beside hi, is off the critical path)
    t1 = x - n * PIO2_1
    p2 = n * PIO2_2
    s2 = t1 - p2
    p3 = n * PIO2_3
    hi = s2 - p3
    lo = (((t1 - s2) - p2) + ((s2 - hi) - p3)) - n * PIO2_3T
    # sin(hi + lo) and cos(hi + lo) on [-pi/4, pi/4]
    z = hi * hi
    w = z * z
    rs = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6)
    v = z * hi
    sin_r = hi - ((z * (0.5 * lo - v * rs) - lo) - v * S1)
    rc = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6))
    hz = 0.5 * z
    one_hz = 1.0 - hz
    cos_r = one_hz + (((1.0 - one_hz) - hz) + (z * rc - hi * lo))
    # the quadrant: n mod 4 = 0, 1, 2, 3 gives (S, C), (C, -S), (-S, -C), (-C, S)
    odd = abs(m) == 1.0
    a = cos_r if odd else sin_r
    b = sin_r if odd else cos_r
    sin_x = -a if (m > 1.5 or m < -0.5) else a
    cos_x = -b if (m > 0.5 or m < -1.5) else b
    return sin_x, cos_x


def sincos(x: float) -> tuple[float, float]:
    """``(sin x, cos x)`` exactly as the compiled model code computes them (to the bit).

    Examples
    --------
    >>> sincos(math.pi / 2)[1] == math.cos(math.pi / 2)
    True
    """
    if abs(x) < LIMIT:  # (False for NaN)
        return sincos_fast(x)
    if math.isinf(x):  # the C library's NaN (Python's math.sin raises an error)
        return math.nan, math.nan
    return math.sin(x), math.cos(x)


def sin(x: float) -> float:
    """``sin x`` as the compiled model code computes it (see :func:`sincos`)."""
    return sincos(x)[0]


def cos(x: float) -> float:
    """``cos x`` as the compiled model code computes it (see :func:`sincos`)."""
    return sincos(x)[1]
