"""What an initial state ends on, each kind spelled once.

An :class:`AttractorKind` is an :class:`~grazing.attractors.classify.Attractor`'s ``kind``: an
attractor (periodic, sticking, neutral, chaotic, quasiperiodic, aperiodic) or an outcome that is none
(escaping, failed, invalid).  Its values are the words that ``--json``, the datasets' ``kind``
variables and the command line print (a string enum as :mod:`grazing.orbits.kinds`' are: it compares
equal to its word and prints as it); its :attr:`~AttractorKind.message` says it in a few words.
"""

from __future__ import annotations

from grazing.orbits.kinds import TextEnum


class AttractorKind(TextEnum):
    """The kind of an attractor or outcome (an :class:`~grazing.attractors.classify.Attractor`'s ``kind``).

    Examples
    --------
    >>> AttractorKind.CHAOTIC == "chaotic", f"{AttractorKind.INVALID}", AttractorKind("failed").outcome
    (True, 'invalid', True)
    >>> AttractorKind.NEUTRAL.message
    'a family of motions (a double multiplier 1), not an isolated attractor'
    """

    PERIODIC = "periodic"
    STICKING = "sticking"
    NEUTRAL = "neutral"
    CHAOTIC = "chaotic"
    QUASIPERIODIC = "quasiperiodic"
    APERIODIC = "aperiodic"
    ESCAPING = "escaping"
    FAILED = "failed"
    INVALID = "invalid"

    @property
    def message(self) -> str:
        """The kind in a few words."""
        return _MESSAGES[self]

    @property
    def outcome(self) -> bool:
        """An outcome, not an attractor (escaping, failed, invalid): matched by kind and reason."""
        return self in OUTCOMES

    @property
    def aperiodic(self) -> bool:
        """An aperiodic attractor (chaotic, quasiperiodic or aperiodic): its points are samples of it."""
        return self in (AttractorKind.CHAOTIC, AttractorKind.QUASIPERIODIC, AttractorKind.APERIODIC)


OUTCOMES = (AttractorKind.ESCAPING, AttractorKind.FAILED, AttractorKind.INVALID)
"""Kinds that are outcomes, not attractors."""

_MESSAGES = {
    AttractorKind.PERIODIC: "a stable periodic orbit",
    AttractorKind.STICKING: "riding on a stop, without impacts",
    AttractorKind.NEUTRAL: "a family of motions (a double multiplier 1), not an isolated attractor",
    AttractorKind.CHAOTIC: "aperiodic, with a positive largest Lyapunov exponent",
    AttractorKind.QUASIPERIODIC: "aperiodic, with a largest Lyapunov exponent near zero",
    AttractorKind.APERIODIC: "aperiodic, without a positive or zero Lyapunov exponent",
    AttractorKind.ESCAPING: "left the bound around the grid, or overflowed",
    AttractorKind.FAILED: "the run failed",
    AttractorKind.INVALID: "beyond a stop: not run",
}
