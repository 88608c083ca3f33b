"""Exceptions raised by grazing; the CLI turns each into one line on stderr."""

from __future__ import annotations


class GrazingError(Exception):
    """Base class of the errors that grazing reports to users.

    Catch it to handle any error of grazing's, whose message is one line that
    names the problem.

    Examples
    --------
    >>> import grazing
    >>> try:
    ...     grazing.models.pendulum("Z")
    ... except grazing.GrazingError as err:
    ...     print(f"{type(err).__name__}: {err}")
    InvalidParameterError: unknown case 'Z' (known: A, B, C, D, A-reduced)
    """


class InvalidParameterError(GrazingError, ValueError):
    """A parameter value is outside its allowed range, not a number, or unknown.

    Also a :class:`ValueError`.

    Examples
    --------
    >>> import grazing
    >>> grazing.models.pendulum("B", r=1.5)
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: r = 1.5 is outside [0, 1] (coefficient of restitution)
    """


class InvalidStateError(GrazingError, ValueError):
    """An initial state is not in the allowed region (for example beyond the stop).

    Also a :class:`ValueError`.

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", theta_hat=math.radians(40))
    >>> grazing.simulate(m, [1.0, 0.0], periods=2)  # 1 rad is past the stop at 40 degrees
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidStateError: initial state [1.0, 0.0] is beyond the stop (guard h = -0.302 < 0)
    """


class UnsupportedExpressionError(GrazingError, ValueError):
    """A model uses a function the Taylor kernels do not expand (a non-smooth or unknown one).

    Also a :class:`ValueError`.

    Examples
    --------
    >>> import sympy as sp, grazing
    >>> x, v, t = sp.symbols("x v t")
    >>> grazing.HybridModel("bad", [x, v], t, [], vector_field=[v, -sp.sign(x)], guard=x + 1,
    ...                     reset=[x, -v], period=1.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grazing.errors.UnsupportedExpressionError: sign is not smooth (sign(x) in the vector field (v')): ...
    """


class SimulationError(GrazingError, RuntimeError):
    """The integration could not be completed (step limit, non-finite state...).

    Also a :class:`RuntimeError`.

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> grazing.simulate(m, [0.0, 0.0], periods=10, max_steps=100)
    Traceback (most recent call last):
    ...
    grazing.errors.SimulationError: step limit of 100 steps reached at t = 46.1425
    """


class ConvergenceError(GrazingError, RuntimeError):
    """A Newton iteration did not converge.

    Also a :class:`RuntimeError`.

    Examples
    --------
    >>> import math, grazing
    >>> from grazing.orbits import find_orbit
    >>> m = grazing.models.pendulum("B", eta=0.46, theta_hat=math.radians(40))
    >>> find_orbit(m, [0.0, 0.0], period=3, max_iter=2)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grazing.errors.ConvergenceError: Newton did not converge to a period-3 orbit: residual 0.0245 after 2 ...
    """


class NotFoundError(GrazingError, LookupError):
    """What was sought does not occur where it was sought (no fold between the start and stop values of a
    branch, say); the message names what was found instead.

    Also a :class:`LookupError`; :func:`grazing.orbits.follow_curve` raises it when the branch
    it starts from has no special point of the kind asked for.

    Examples
    --------
    >>> from grazing.errors import NotFoundError
    >>> try:
    ...     raise NotFoundError("no fold on the period-1 branch from eta = 0.3 to 0.4: met no special point")
    ... except LookupError as err:
    ...     print(err)
    no fold on the period-1 branch from eta = 0.3 to 0.4: met no special point
    """


class ForeignFileError(InvalidParameterError):
    """An output's path holds a file grazing did not write (or one changed since): it is left as it is.

    An :class:`InvalidParameterError` (the path given is the bad parameter).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from grazing.outputs import write_json
    >>> path = Path(tempfile.mkdtemp()) / "notes.json"
    >>> _ = path.write_text("{}")  # a file of the user's
    >>> write_json(path, {"period": 5})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grazing.errors.ForeignFileError: .../notes.json exists and was not written by grazing ...
    >>> path.read_text()
    '{}'
    """


class WriteError(GrazingError, OSError):
    """A file could not be written (a full disk, a read-only folder...); nothing was written.

    Also an :class:`OSError`.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from grazing.outputs import write_json
    >>> write_json(Path(tempfile.mkdtemp()) / "no-such-folder" / "out.json", {"period": 5})
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    grazing.errors.WriteError: cannot write .../no-such-folder/out.json: ...; nothing was written
    """


class GrazingWarning(UserWarning):
    """A result that was computed as asked but is not a motion of the system (the CLI prints it as a note).

    A :class:`UserWarning`: :func:`grazing.orbits.find_grazings` warns with it
    when a grazing orbit computed with the stops ignored passes through another
    stop.  Turn it into an error to stop at such a result:

    Examples
    --------
    >>> import warnings
    >>> from grazing.errors import GrazingWarning
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error", GrazingWarning)
    ...     try:
    ...         warnings.warn("this grazing passes through stop 'back'", GrazingWarning)
    ...     except GrazingWarning as w:
    ...         print(w)
    this grazing passes through stop 'back'
    """
