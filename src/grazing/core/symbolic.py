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

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    import sympy as sp


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
    """

    states: tuple[sp.Symbol, ...]
    time: sp.Symbol
    params: tuple[sp.Symbol, ...]
    vector_field: tuple[sp.Expr, ...]
    guard: sp.Expr
    reset: tuple[sp.Expr, ...]
    contact_direction: tuple[sp.Expr, ...] | None = None
    period: sp.Expr | None = None

    def canonical(self) -> SymbolicSystem:
        """The same system with every user symbol replaced by a fresh :class:`sympy.Dummy`.

        The code generator creates symbols of its own (the variational matrix,
        common subexpressions); working on the canonical system guarantees that
        no name a user chooses for a state, parameter or time (``v1``, ``t_0``,
        ``pi``, ``sin`` ...) can be the same sympy object as one of those.
        """
        import sympy as sp

        sub = {x: sp.Dummy(f"x{i}") for i, x in enumerate(self.states)}
        sub[self.time] = sp.Dummy("t")
        sub.update({p: sp.Dummy(f"p{i}") for i, p in enumerate(self.params)})

        def tr(e: sp.Expr) -> sp.Expr:
            return sp.sympify(e).xreplace(sub)

        return SymbolicSystem(
            states=tuple(sub[x] for x in self.states),
            time=sub[self.time],
            params=tuple(sub[p] for p in self.params),
            vector_field=tuple(tr(e) for e in self.vector_field),
            guard=tr(self.guard),
            reset=tuple(tr(e) for e in self.reset),
            contact_direction=(
                None if self.contact_direction is None else tuple(map(tr, self.contact_direction))
            ),
            period=None if self.period is None else tr(self.period),
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
