"""The experimental rig of the paper (section 2.1) and its dimensional conversions.

The pendulum of Piiroinen, Virgin & Champneys (2004) has an effective length
``L = 225 mm``, swings on a plane inclined so that the effective gravity is
``g_e = 0.24 g``, and its pivot is shaken with amplitude ``A = 50.8 mm``.  The
model's frequency ratio is ``eta = omega / omega_0`` with
``omega_0 = 2 sqrt(g_e / L)`` (paper eq. 3), the small-amplitude frequency of
the impacting oscillator with the stop at equilibrium, which is twice the
pendulum's own natural frequency.

Damping: the model's equation of motion (paper eq. 4, the authoritative form)
follows from eq. 2 with ``beta = kappa / (2 omega_0)``, as eq. 3 prints.  The
paper's quoted values, however, (``kappa = 1.1`` for ``beta = 0.0426``,
``kappa = 1.238`` for ``beta = 0.048``) fit ``kappa = 4 omega_0 beta``
(docs/equations.md, errata).  :meth:`Apparatus.kappa` offers both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

STANDARD_GRAVITY = 9.81
"""g in m/s^2, as the paper uses it."""


@dataclass(frozen=True)
class Apparatus:
    """Dimensions of an impacting-pendulum rig.

    Attributes
    ----------
    length
        Effective length ``L`` of the ideal pendulum, in metres.
    g_effective
        Effective gravity ``g_e`` along the inclined plane, in m/s^2.
    amplitude
        Amplitude ``A`` of the pivot's harmonic motion, in metres.

    Examples
    --------
    >>> rig = Apparatus()
    >>> round(rig.omega0, 4), round(rig.alpha, 4)
    (6.4696, 0.2258)
    >>> round(rig.forcing_hz(0.446), 5), round(rig.eta(rig.forcing_hz(0.446)), 12)
    (0.45923, 0.446)
    """

    length: float = 0.225
    g_effective: float = 0.24 * STANDARD_GRAVITY
    amplitude: float = 0.0508

    def __post_init__(self) -> None:
        for name in ("length", "g_effective", "amplitude"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a positive number, got {v!r}")

    @property
    def omega0(self) -> float:
        """``omega_0 = 2 sqrt(g_e / L)`` in rad/s (paper eq. 3)."""
        return 2.0 * math.sqrt(self.g_effective / self.length)

    @property
    def alpha(self) -> float:
        """The forcing amplitude ``alpha = A / L`` (0.2258 for the paper's rig)."""
        return self.amplitude / self.length

    def eta(self, forcing_hz: float) -> float:
        """Frequency ratio ``eta = 2 pi f / omega_0`` of a forcing frequency in Hz."""
        return 2.0 * math.pi * float(forcing_hz) / self.omega0

    def forcing_hz(self, eta: float) -> float:
        """Forcing frequency in Hz of a frequency ratio ``eta``."""
        return float(eta) * self.omega0 / (2.0 * math.pi)

    def omega(self, eta: float) -> float:
        """Forcing angular frequency ``omega = eta omega_0`` in rad/s (``tau = omega t``)."""
        return float(eta) * self.omega0

    def kappa(self, beta: float, convention: str = "eq4") -> float:
        """Dimensional damping ``kappa`` (1/s) of the model's ``beta``.

        ``convention="eq4"``: ``kappa = 2 omega_0 beta``, the relation under
        which eq. 2 becomes the model's eq. 4.  ``convention="paper"``:
        ``kappa = 4 omega_0 beta``, the relation the paper's quoted numbers
        follow.

        Examples
        --------
        >>> rig = Apparatus()
        >>> round(rig.kappa(0.0426, "paper"), 2), round(rig.kappa(0.0426), 3)
        (1.1, 0.551)
        """
        if convention not in ("eq4", "paper"):
            raise ValueError(f"convention must be 'eq4' or 'paper', got {convention!r}")
        return (2.0 if convention == "eq4" else 4.0) * self.omega0 * float(beta)


PAPER_RIG = Apparatus()
"""The paper's rig: L = 225 mm, g_e = 0.24 g, A = 50.8 mm."""
