"""The symbolic form of a hybrid model: what the code generator and the analysis need.

:class:`SymbolicSystem` holds the sympy expressions of a model (vector field,
guard, reset, contact direction, period) and derives from them what the
engine and the analysis use: Lie derivatives of the guard (its rate
``L_f h`` and acceleration ``L_f^2 h``), the sticking vector field, and a
*canonical* copy in which every user symbol is replaced by a fresh
:class:`sympy.Dummy`, so that no name a user chooses can collide with a symbol
the code generator creates.  sympy is imported only when a method needs it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    import sympy as sp


@dataclass(frozen=True)
class Stop:
    """One stop of a hybrid model: where impacts happen and what they do.

    Attributes
    ----------
    name
        The stop's name (``"right"``, ``"left"``, ``"back"``), used in results
        and on the command line.
    guard
        ``h(x, t)``: positive in the allowed region, zero on this stop.
    reset
        ``g(x, t)``: the state just after an impact on this stop.
    contact_direction
        Direction in which the reset acts (for a mechanical impact, the
        velocity direction): with it, complete chattering on this stop is
        summed and continued as sticking; without it an accumulation of
        impacts on this stop stops the run.

    Examples
    --------
    >>> import sympy as sp
    >>> x, v, r = sp.symbols("x v r")
    >>> Stop("right", 1 - x, [x, -r * v], contact_direction=[0, 1]).name
    'right'
    """

    name: str
    guard: Any
    reset: Sequence[Any]
    contact_direction: Sequence[Any] | None = None


@dataclass(frozen=True)
class Mode:
    """One mode of a model with several vector fields: its field and its impacts.

    Attributes
    ----------
    name
        The mode's name (an identifier: ``"free"``, ``"contact"``), used in
        results and messages.
    vector_field
        ``f(x, t)`` while the motion is in this mode, one expression per state.
    stops
        Impacts in this mode (:class:`Stop`): transitions back to the same mode
        with a reset.

    Examples
    --------
    >>> import sympy as sp
    >>> x, v = sp.symbols("x v")
    >>> Mode("free", [v, -x]).name
    'free'
    """

    name: str
    vector_field: Sequence[Any]
    stops: Sequence[Stop] = ()


@dataclass(frozen=True)
class Transition:
    """A switch from one mode to another when a guard reaches zero.

    Attributes
    ----------
    name
        The transition's name (an identifier, distinct from every stop's).
    source, target
        The names of the modes it leaves and enters.
    guard
        ``h(x, t)``: positive while in ``source``; the switch happens when it reaches 0.
    reset
        ``g(x, t)``, the state after the switch; ``None``: no reset (the state
        is continuous, only the vector field changes, as at a compliant stop).
    contact_direction
        As :attr:`Stop.contact_direction`, for a transition with a reset.

    Examples
    --------
    >>> import sympy as sp
    >>> x = sp.Symbol("x")
    >>> Transition("touch", "free", "contact", 1 - x).reset is None
    True
    """

    name: str
    source: str
    target: str
    guard: Any
    reset: Sequence[Any] | None = None
    contact_direction: Sequence[Any] | None = None


@dataclass(frozen=True)
class Surface:
    """A switching surface ``h(x, t) = 0`` between two modes, crossed both ways without a reset.

    Attributes
    ----------
    name
        The surface's name; its two transitions are ``{name}_to_{negative}``
        (``h`` reaches 0 from above) and ``{name}_to_{positive}`` (from below).
    h
        The surface's function.
    positive, negative
        The modes on the sides ``h > 0`` and ``h < 0``.
    sliding
        Where both fields push towards the surface the motion slides on it
        (Filippov's convex combination, :meth:`SymbolicSystem.filippov_field`).

    Examples
    --------
    >>> import sympy as sp
    >>> v = sp.Symbol("v")
    >>> Surface("belt", v - 1, "slip_back", "slip_forward").positive
    'slip_back'
    """

    name: str
    h: Any
    positive: str
    negative: str
    sliding: bool = True


@dataclass(frozen=True)
class SlidingMode:
    """Where a sliding pseudo-mode sits among modes and transitions (:meth:`SymbolicSystem.sliding_modes`).

    Attributes
    ----------
    surface
        The index of its surface (into :attr:`SymbolicSystem.surfaces`).
    name
        ``"sliding on 'belt'"``.
    mode
        Its mode index (after the real modes).
    base
        The index of its first virtual transition (exit to the positive side;
        then the exit to the negative side, the entry from the positive side and
        the entry from the negative side).
    positive, negative
        The indices of the modes on the sides ``h > 0`` and ``h < 0``.
    down, up
        The surface's transitions from the positive side (guard ``h``) and from
        the negative side (guard ``-h``).
    """

    surface: int
    name: str
    mode: int
    base: int
    positive: int
    negative: int
    down: int
    up: int


@dataclass(frozen=True)
class SymbolicSystem:
    """The symbolic pieces of a hybrid model that the code generator needs.

    Attributes
    ----------
    states, time, params
        Symbols of the state vector, time and parameters (in the order of the
        parameter vector).
    vector_field
        ``f(x, t)``, one expression per state.
    guard
        ``h(x, t)``; the allowed region is ``h > 0``, impacts happen when ``h``
        reaches 0.
    reset
        ``g(x, t)``, the state just after an impact.
    contact_direction
        Direction ``e(x, t)`` along which the reset changes the state (the
        velocity direction of a mechanical impact), used to constrain the flow
        to the stop during sticking; ``None`` disables sticking.
    stops
        Every stop (:class:`Stop`, expressions sympified); ``guard``, ``reset``
        and ``contact_direction`` are those of the first, and
        :meth:`at_stop` gives the system seen from any other.
    modes
        A model with several modes: each mode's name and vector field (as
        :class:`Mode`, without stops), the first the initial mode's field
        ``vector_field``; empty for a model of one mode.  Then ``stops`` are
        every transition (an impact's reset, or the identity for a switch),
        ``sources``/``targets`` their modes' indices and ``resets`` whether
        they have a reset of their own.
    surfaces
        The model's switching surfaces (:class:`Surface`, ``h`` sympified).
    """

    states: tuple[sp.Symbol, ...]
    time: sp.Symbol
    params: tuple[sp.Symbol, ...]
    vector_field: tuple[sp.Expr, ...]
    guard: sp.Expr
    reset: tuple[sp.Expr, ...]
    contact_direction: tuple[sp.Expr, ...] | None = None
    period: sp.Expr | None = None
    stops: tuple[Stop, ...] = ()
    modes: tuple[Mode, ...] = ()
    sources: tuple[int, ...] = ()
    targets: tuple[int, ...] = ()
    resets: tuple[bool, ...] = ()
    surfaces: tuple[Surface, ...] = ()

    def __post_init__(self) -> None:
        if not self.stops:
            stop = Stop("stop", self.guard, tuple(self.reset), self.contact_direction)
            object.__setattr__(self, "stops", (stop,))

    @property
    def stop_names(self) -> tuple[str, ...]:
        return tuple(stop.name for stop in self.stops)

    @property
    def mode_names(self) -> tuple[str, ...]:
        return tuple(mode.name for mode in self.modes)

    def at_mode(self, index: int) -> SymbolicSystem:
        """The same system with mode ``index``'s vector field as *the* vector field (itself without modes)."""
        if not self.modes:
            return self
        return dataclasses.replace(self, vector_field=tuple(self.modes[index].vector_field))

    def at_stop(self, index: int) -> SymbolicSystem:
        """The same system with stop ``index``'s guard, reset and contact direction as *the* stop.

        With several modes, a stop is any transition and the vector field is its source mode's.
        """
        stop = self.stops[index]
        return dataclasses.replace(
            self.at_mode(self.sources[index]) if self.modes else self,
            guard=stop.guard,
            reset=tuple(stop.reset),
            contact_direction=None if stop.contact_direction is None else tuple(stop.contact_direction),
        )

    def canonical(self) -> SymbolicSystem:
        """The same system with every user symbol replaced by a fresh :class:`sympy.Dummy`.

        The code generator creates symbols of its own (the variational matrix,
        common subexpressions); working on the canonical system guarantees that
        no name a user chooses for a state, parameter or time (``v1``, ``t_0``,
        ``pi``, ``sin`` ...) can be the same sympy object as one of those.  The
        reciprocal functions are written as ``1 / f``
        (:func:`grazing.core.expressions.smooth_form`).
        """
        import sympy as sp

        from grazing.core.expressions import smooth_form

        sub = {x: sp.Dummy(f"x{i}") for i, x in enumerate(self.states)}
        sub[self.time] = sp.Dummy("t")
        sub.update({p: sp.Dummy(f"p{i}") for i, p in enumerate(self.params)})

        def tr(e: sp.Expr) -> sp.Expr:
            return smooth_form(sp.sympify(e).xreplace(sub))

        def cd(d: Sequence[Any] | None) -> tuple[sp.Expr, ...] | None:
            return None if d is None else tuple(map(tr, d))

        return SymbolicSystem(
            states=tuple(sub[x] for x in self.states),
            time=sub[self.time],
            params=tuple(sub[p] for p in self.params),
            vector_field=tuple(tr(e) for e in self.vector_field),
            guard=tr(self.guard),
            reset=tuple(tr(e) for e in self.reset),
            contact_direction=cd(self.contact_direction),
            period=None if self.period is None else tr(self.period),
            stops=tuple(
                Stop(st.name, tr(st.guard), tuple(tr(e) for e in st.reset), cd(st.contact_direction))
                for st in self.stops
            ),
            modes=tuple(Mode(md.name, tuple(tr(e) for e in md.vector_field)) for md in self.modes),
            sources=self.sources,
            targets=self.targets,
            resets=self.resets,
            surfaces=tuple(dataclasses.replace(sf, h=tr(sf.h)) for sf in self.surfaces),
        )

    def gradient(self, expr: sp.Expr) -> list[sp.Expr]:
        import sympy as sp

        return [sp.diff(expr, x) for x in self.states]

    def lie(self, expr: sp.Expr) -> sp.Expr:
        """Derivative of ``expr`` along the flow: grad(expr) . f + d(expr)/dt."""
        import sympy as sp

        return sp.Add(*[g * f for g, f in zip(self.gradient(expr), self.vector_field)]) + sp.diff(
            expr, self.time
        )

    @property
    def normal_rate(self) -> sp.Expr:
        """``L_f h``: rate of change of the guard (negative when approaching)."""
        return self.lie(self.guard)

    @property
    def normal_accel(self) -> sp.Expr:
        """``L_f^2 h``: the guard's acceleration (negative when pushed into the stop)."""
        return self.lie(self.normal_rate)

    def sticking_field(self) -> tuple[sp.Expr, ...]:
        """Vector field constrained to ``h = 0, L_f h = 0`` along the contact direction."""
        import sympy as sp

        if self.contact_direction is None:
            raise ValueError("model has no contact direction")
        e = self.contact_direction
        gr = self.gradient(self.normal_rate)
        den = sp.Add(*[g * ei for g, ei in zip(gr, e)])
        lam = self.normal_accel / den
        return tuple(f - lam * ei for f, ei in zip(self.vector_field, e))

    def surface_sides(self, index: int) -> tuple[SymbolicSystem, SymbolicSystem]:
        """The systems of surface ``index``'s positive and negative modes."""
        sf = self.surfaces[index]
        names = self.mode_names
        return self.at_mode(names.index(sf.positive)), self.at_mode(names.index(sf.negative))

    def filippov_field(self, index: int) -> tuple[sp.Expr, ...]:
        """The sliding vector field on surface ``index`` (Filippov's convex combination).

        ``f_s = f_+ + w (f_- - f_+)`` with ``w = L_+ h / (L_+ h - L_- h)``, where
        ``f_+`` is the field of the side ``h > 0`` and ``f_-`` that of ``h < 0``
        and the Lie derivatives include ``dh/dt``: ``L_{f_s} h = 0`` identically,
        so the flow of ``f_s`` stays on the surface.
        """
        pos, neg = self.surface_sides(index)
        h = self.surfaces[index].h
        lp, ln = pos.lie(h), neg.lie(h)
        weight = lp / (lp - ln)
        return tuple(fp + weight * (fn - fp) for fp, fn in zip(pos.vector_field, neg.vector_field))

    def sliding_modes(self) -> tuple[SlidingMode, ...]:
        """The sliding pseudo-modes of a model with modes, one per surface with ``sliding=True``.

        Pseudo-mode ``i`` has the mode index ``len(modes) + i`` (after the real
        modes) and the transition indices ``len(stops) + 4 i + c`` after the real
        transitions: ``c = 0, 1`` the exits to the positive and to the negative
        side (its first two event rows, :meth:`exit_rows`), ``c = 2, 3`` the
        entries from the positive and from the negative side (recorded as
        switches; located as the crossings of the surface's transitions).
        """
        out = []
        names = self.mode_names
        stops = self.stop_names
        for k, sf in enumerate(self.surfaces):
            if not sf.sliding:
                continue
            out.append(SlidingMode(
                surface=k, name=f"sliding on {sf.name!r}", mode=len(self.modes) + len(out),
                base=len(self.stops) + 4 * len(out), positive=names.index(sf.positive),
                negative=names.index(sf.negative), down=stops.index(f"{sf.name}_to_{sf.negative}"),
                up=stops.index(f"{sf.name}_to_{sf.positive}"),
            ))  # fmt: skip
        return tuple(out)

    def exit_rows(self, index: int) -> tuple[sp.Expr, sp.Expr]:
        """``(-L_+ h, L_- h)`` of surface ``index``: both positive while sliding, one reaches 0 at an exit."""
        pos, neg = self.surface_sides(index)
        h = self.surfaces[index].h
        return -pos.lie(h), neg.lie(h)
