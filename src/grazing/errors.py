"""Exceptions raised by grazing; the CLI turns each into one line on stderr."""

from __future__ import annotations


class GrazingError(Exception):
    """Base class of the errors that grazing reports to users."""


class InvalidParameterError(GrazingError, ValueError):
    """A parameter value is outside its allowed range, not a number, or unknown."""


class InvalidStateError(GrazingError, ValueError):
    """An initial state is not in the allowed region (for example beyond the stop)."""


class UnsupportedExpressionError(GrazingError, ValueError):
    """A model uses a function the Taylor kernels do not expand (a non-smooth or unknown one)."""


class SimulationError(GrazingError, RuntimeError):
    """The integration could not be completed (step limit, non-finite state...)."""


class ConvergenceError(GrazingError, RuntimeError):
    """A Newton iteration did not converge."""


class NotFoundError(GrazingError, LookupError):
    """What was sought does not occur where it was sought (no fold between the start and stop values of a
    branch, say); the message names what was found instead."""


class ForeignFileError(InvalidParameterError):
    """An output's path holds a file grazing did not write (or one changed since): it is left as it is."""


class WriteError(GrazingError, OSError):
    """A file could not be written (a full disk, a read-only folder...); nothing was written."""


class GrazingWarning(UserWarning):
    """A result that was computed as asked but is not a motion of the system (the CLI prints it as a note)."""
