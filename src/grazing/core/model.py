"""The hybrid model type: vector field, guard, reset, Jacobians and parameters.

A hybrid (impacting) system in the sense of the paper's eqs. (9)-(10) is

    x' = f(x, t)        while h(x, t) > 0,
    x <- g(x, t)        when h(x, t) reaches 0.

Models are written symbolically with sympy; the Jacobians ``f_x``, ``h_x``,
``g_x`` (what the saltation matrix, paper eq. 14, needs) are derived
automatically, and the engine generates and caches compiled kernels for them.
A :class:`HybridModel` also carries parameter values; :meth:`with_params`
returns a copy with other values that shares the compiled kernels.

This module imports nothing from the engine: the engine registers the function
that builds a model's compiled kernels (:func:`set_kernel_loader`) when it is
imported, which ``import grazing`` does.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from grazing.core.expressions import check_expression
from grazing.core.symbolic import Mode, Stop, Surface, SymbolicSystem, Transition
from grazing.errors import InvalidParameterError, InvalidStateError

KernelLoader = Callable[["_Definition", int, "int | None"], Any]
"""``loader(definition, directions, order) -> module``: builds (or loads from the cache) the
compiled kernels of a model definition; ``order=None`` is the engine's default order."""

_kernel_loader: KernelLoader | None = None


def set_kernel_loader(loader: KernelLoader) -> None:
    """Register the engine's kernel builder (done by :mod:`grazing.engine.codegen` on import)."""
    global _kernel_loader
    _kernel_loader = loader


ON_STOP_TOL = 1e-9
"""A state whose guard is above ``-ON_STOP_TOL * max(1, |x|)`` counts as on the stop, not beyond
it (a state sampled while sticking, or an impact state, is on the stop only to rounding)."""


@dataclass(frozen=True)
class Parameter:
    """A named model parameter with a default value, an allowed interval and display metadata.

    Attributes
    ----------
    name
        The parameter's name in the model's expressions (``sympy.Symbol(name)``).
    default
        Its default value, in the model's own unit.
    lower, upper, lower_open, upper_open
        The allowed interval.
    description
        A few words saying what it is (used in messages).
    unit
        The unit of the value in the model (``"rad"``, ``"m"``...), for labels.
    symbol
        How to print it (``"θ̂"``, ``"η"``); the name if empty.
    angle
        An angle in radians in the model, shown and entered in degrees on the
        command line and in plots.

    Examples
    --------
    >>> r = Parameter("r", 0.8, lower=0.0, upper=1.0, description="restitution")
    >>> r.check(0.5)
    0.5
    >>> r.check(1.5)
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: r = 1.5 is outside [0, 1] (restitution)
    >>> Parameter("r", 1.5, lower=0.0, upper=1.0)
    Traceback (most recent call last):
    ...
    grazing.errors.InvalidParameterError: the default of parameter r is invalid: r = 1.5 is outside [0, 1]
    >>> stop = Parameter("theta_hat", 0.7, unit="rad", symbol="θ̂", angle=True)
    >>> round(stop.to_display(0.7), 3), stop.display_unit, stop.label
    (40.107, 'deg', 'θ̂')
    """

    name: str
    default: float
    lower: float = -math.inf
    upper: float = math.inf
    lower_open: bool = False
    upper_open: bool = False
    description: str = ""
    unit: str = ""
    symbol: str = ""
    angle: bool = False

    @property
    def label(self) -> str:
        """The symbol to print (the name when no symbol is given)."""
        return self.symbol or self.name

    @property
    def display_unit(self) -> str:
        """The unit values are shown and entered in: degrees for angles, else :attr:`unit`."""
        return "deg" if self.angle else self.unit

    def to_display(self, value: float) -> float:
        """A model value in the display unit (degrees for angles)."""
        return math.degrees(value) if self.angle else float(value)

    def from_display(self, value: float) -> float:
        """A value given in the display unit, in the model's unit (radians for angles)."""
        return math.radians(value) if self.angle else float(value)

    def show(self, value: float, spec: str = ".10g") -> str:
        """``name = value unit`` with a model value in the display unit, as messages print it.

        Examples
        --------
        >>> Parameter("theta_hat", 0.7, unit="rad", angle=True).show(0.7, ".4g")
        'theta_hat = 40.11 deg'
        >>> Parameter("eta", 0.4).show(0.4451211835)
        'eta = 0.4451211835'
        """
        unit = f" {self.display_unit}" if self.display_unit else ""
        return f"{self.name} = {self.to_display(value):{spec}}{unit}"

    def show_range(self, lo: float, hi: float, spec: str = "g") -> str:
        """``name in [lo, hi] unit`` with model values in the display unit, as messages print it.

        >>> Parameter("theta_hat", 0.7, unit="rad", angle=True).show_range(0.5235987756, 0.6108652382)
        'theta_hat in [30, 35] deg'
        """
        unit = f" {self.display_unit}" if self.display_unit else ""
        return f"{self.name} in [{self.to_display(lo):{spec}}, {self.to_display(hi):{spec}}]{unit}"

    def interval(self) -> str:
        def fmt(v: float) -> str:
            return f"{v:g}"

        lo = "(" if self.lower_open or math.isinf(self.lower) else "["
        hi = ")" if self.upper_open or math.isinf(self.upper) else "]"
        return f"{lo}{fmt(self.lower)}, {fmt(self.upper)}{hi}"

    def __post_init__(self) -> None:
        if not self.lower <= self.upper:
            raise InvalidParameterError(
                f"parameter {self.name}: lower={self.lower:g}, upper={self.upper:g} is not an interval"
            )
        try:
            self.check(self.default)
        except InvalidParameterError as exc:
            raise InvalidParameterError(f"the default of parameter {self.name} is invalid: {exc}") from None

    def check(self, value: Any) -> float:
        """Return ``value`` as a float, or raise :class:`InvalidParameterError`."""
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise InvalidParameterError(f"{self.name} must be a number, got {value!r}") from None
        if not math.isfinite(v):
            raise InvalidParameterError(f"{self.name} must be finite, got {v}")
        below = v < self.lower or (self.lower_open and v == self.lower)
        above = v > self.upper or (self.upper_open and v == self.upper)
        if below or above:
            what = f" ({self.description})" if self.description else ""
            raise InvalidParameterError(f"{self.name} = {_value_text(v)} is outside {self.interval()}{what}")
        return v

    def admits(self, values: np.ndarray) -> np.ndarray:
        """Which of the float ``values`` :meth:`check` accepts (a boolean array, at once).

        Examples
        --------
        >>> r = Parameter("r", 0.5, lower=0.0, upper=1.0, lower_open=True)
        >>> r.admits(np.array([0.0, 0.5, 1.0, np.nan]))
        array([False,  True,  True, False])
        """
        below = (values < self.lower) | (self.lower_open & (values == self.lower))
        above = (values > self.upper) | (self.upper_open & (values == self.upper))
        return np.isfinite(values) & ~below & ~above


def _value_text(v: float) -> str:
    """``v`` as ``:g`` prints it, or all its digits where ``:g`` would round it (``r = 1.0000001`` outside
    ``[0, 1]``, not ``r = 1``).

    >>> _value_text(2.0), _value_text(1.0000001), _value_text(-1e-9)
    ('2', '1.0000001', '-1e-09')
    """
    short = f"{v:g}"
    return short if float(short) == v else repr(v)


class _Definition:
    """The parameter-independent part of a model, shared by all its copies.

    Either eager (user models: the sympy pieces are given and validated at
    once) or lazy (built-in models: ``builder()`` returns them on first use, so
    that a model whose kernels are already compiled and cached is used without
    importing sympy at all).
    """

    @classmethod
    def get(cls, kwargs: dict[str, Any]) -> _Definition:
        """The definition for these constructor arguments, reusing an existing one."""
        digest = hashlib.sha256(_srepr(sorted(kwargs.items())).encode()).hexdigest()
        found = _DEFINITIONS.get(digest)
        if found is None:
            found = cls(**kwargs)
            found.args = kwargs
            _DEFINITIONS[digest] = found
        return found

    def __init__(
        self,
        *,
        name: str,
        parameters: Sequence[Parameter],
        state_names: Sequence[str],
        period: Any,
        periodic: bool,
        state_labels: Sequence[str] | None,
        description: str,
        reference: str,
        symbolic: dict[str, Any] | None = None,
        builder: Callable[[], dict[str, Any]] | None = None,
        state_units: Sequence[str] | None = None,
        time_label: str | None = None,
        stop_names: Sequence[str] | None = None,
    ):
        self.name = name
        self.parameters = tuple(parameters)
        pnames = [p.name for p in self.parameters]
        if len(set(pnames)) != len(pnames):
            raise ValueError("parameter names must be unique")
        self.state_names = tuple(state_names)
        self.state_labels = tuple(state_labels) if state_labels else self.state_names
        self.state_units = tuple(state_units) if state_units else ("",) * len(self.state_names)
        if len(self.state_labels) != len(self.state_names) or len(self.state_units) != len(self.state_names):
            raise ValueError("state_labels and state_units need one entry per state")
        self.time_label = time_label
        self.mode_names: tuple[str, ...] = ("free",)
        self.transition_modes: tuple[tuple[str, str], ...] | None = None
        self.transition_resets: tuple[bool, ...] | None = None  # (a model with modes: per transition)
        self.sliding_switches: tuple[tuple[str, str, str], ...] = ()
        self.surface_names: tuple[str, ...] = ()
        self.sliding_surfaces: tuple[int, ...] = ()  # the surfaces with sliding=True (indices)
        if symbolic is not None and "modes" in symbolic:
            self.mode_names = tuple(md[0] for md in symbolic["modes"])
            bad_modes = [nm for nm in self.mode_names if not (isinstance(nm, str) and nm.isidentifier())]
            if not self.mode_names or bad_modes or len(set(self.mode_names)) != len(self.mode_names):
                raise ValueError(f"mode names must be distinct identifiers, got {list(self.mode_names)}")
            layout = _transition_layout(symbolic)
            stop_names = [item[0] for item in layout]
            self.transition_modes = tuple((item[1], item[2]) for item in layout)
            self.transition_resets = tuple(item[4] is not None for item in layout)
            self.surface_names = tuple(sf[0] for sf in symbolic["surfaces"])
            self.sliding_surfaces = tuple(i for i, sf in enumerate(symbolic["surfaces"]) if sf[4])
            pseudo, self.sliding_switches = _sliding_layout(symbolic)
            self.mode_names += pseudo
            if not stop_names:
                raise ValueError("a model with modes needs at least one transition, stop or surface")
        elif symbolic is not None:
            stop_names = [st[0] for st in symbolic["stops"]] if "stops" in symbolic else ["stop"]
        self.stop_names = tuple(stop_names or ("stop",))
        bad = [nm for nm in self.stop_names if not (isinstance(nm, str) and nm.isidentifier())]
        if bad or len(set(self.stop_names)) != len(self.stop_names):
            what = "stop" if self.transition_modes is None else "stop and transition"
            raise ValueError(f"{what} names must be distinct identifiers, got {list(self.stop_names)}")
        self.period_expr = period
        self.period_str = str(period)
        self.periodic = periodic
        self.description = description
        self.reference = reference
        self._symbolic = symbolic
        self._builder = builder
        self._system: SymbolicSystem | None = None
        self._kernels: dict[tuple[int, int], Any] = {}
        self._numeric: dict[tuple[str, int], Callable[..., Any]] = {}
        if symbolic is not None:
            self.system  # noqa: B018 - validate user models at construction
            self._period_fn = _compiled_period(self.system)
        else:
            # Built-in (lazy) models give the period as text in their parameter names.
            try:
                code = compile(f"lambda {', '.join(pnames) or '_'}: {period}", "<period>", "eval")
                self._period_fn = eval(code, {**vars(math), "__builtins__": {}})  # the period's text
            except SyntaxError:
                raise ValueError(f"cannot evaluate the period expression {period!r}") from None

    @property
    def system(self) -> SymbolicSystem:
        """The symbolic vector field, guard and reset (built and validated on first use)."""
        if self._system is None:
            import sympy as sp

            pieces = self._symbolic if self._symbolic is not None else self._builder()  # type: ignore[misc]
            psyms = tuple(sp.Symbol(p.name) for p in self.parameters)
            states, time = tuple(pieces["states"]), pieces["time"]
            names = [str(x) for x in states] + [str(time)] + [p.name for p in self.parameters]
            clash = sorted({nm for nm in names if names.count(nm) > 1})
            if clash:
                raise ValueError(
                    f"the names of states, time and parameters must differ; used twice: {', '.join(clash)}"
                )
            local = {str(sym): sym for sym in (*states, time, *psyms)}

            def expr(e: Any) -> Any:
                # Text is read with the model's own names (a state called "E" or "pi" is that state).
                return sp.sympify(e, locals=local) if isinstance(e, str) else sp.sympify(e)

            if "modes" in pieces:
                self._system = _modes_system(pieces, states, time, psyms, expr(self.period_expr), expr)
                return self._system
            raw = pieces.get("stops")
            if raw is None:
                raw = [("stop", pieces["guard"], pieces["reset"], pieces.get("contact_direction"))]
            stops = []
            for item in raw:
                name, guard, reset, cd = (
                    (item.name, item.guard, item.reset, item.contact_direction)
                    if isinstance(item, Stop)
                    else item
                )
                stops.append(Stop(
                    name, expr(guard), tuple(expr(e) for e in reset),
                    None if cd is None else tuple(expr(e) for e in cd),
                ))  # fmt: skip
            if tuple(st.name for st in stops) != self.stop_names:
                raise ValueError(
                    f"the model's stops are {[st.name for st in stops]}, declared {list(self.stop_names)}"
                )
            system = SymbolicSystem(
                states=states,
                time=time,
                params=psyms,
                vector_field=tuple(expr(e) for e in pieces["vector_field"]),
                guard=stops[0].guard,
                reset=tuple(stops[0].reset),
                contact_direction=None
                if stops[0].contact_direction is None
                else tuple(stops[0].contact_direction),
                period=expr(self.period_expr),
                stops=tuple(stops),
            )
            n = len(states)
            if len(system.vector_field) != n:
                raise ValueError("vector_field needs one expression per state")
            for st in stops:
                if len(st.reset) != n:
                    raise ValueError(f"the reset of stop {st.name!r} needs one expression per state")
                if st.contact_direction is not None and len(st.contact_direction) != n:
                    raise ValueError(
                        f"the contact_direction of stop {st.name!r} needs one expression per state"
                    )
            allowed = set(states) | {time} | set(psyms)
            for e in [*system.vector_field, *(e for st in stops for e in (st.guard, *st.reset))]:
                extra = e.free_symbols - allowed
                if extra:
                    raise ValueError(f"unknown symbols {sorted(map(str, extra))} in {e}")
            if system.period.free_symbols - set(psyms):
                raise ValueError("the period may depend on parameters only")
            for where, e in _expressions(system):
                check_expression(e, where)
            self._system = system
        return self._system

    def identity(self) -> str:
        """Text that determines the compiled kernels (without building them)."""
        if self._builder is not None:
            import inspect

            source = inspect.getsource(self._builder)
        else:
            source = _srepr(sorted((self._symbolic or {}).items()))
        period = _srepr(self.period_expr)
        return repr((self.name, [p.name for p in self.parameters], period, self.periodic, source))

    def kernels(self, directions: int = 0, order: int | None = None) -> Any:
        if (directions, order) not in self._kernels:
            if _kernel_loader is None:  # pragma: no cover - import grazing registers the engine's
                raise RuntimeError("no kernel loader registered: import grazing (or grazing.engine) first")
            self._kernels[directions, order] = _kernel_loader(self, directions, order)
        return self._kernels[directions, order]

    def scalar_kernels(self) -> Any:
        """Kernels for the scalar functions (vector field, guard, reset, ...), which every module has:
        one already loaded (a sweep's, say: no second module to load), else the default one."""
        if self._kernels:
            return next(iter(self._kernels.values()))
        return self.kernels()

    def numeric(self, what: str, stop: int = 0) -> Callable[..., Any]:
        """numpy function of ``(x, t, p)`` for f, h, g or a Jacobian at a stop (built on first use)."""
        fn = self._numeric.get((what, stop))
        if fn is None:
            import sympy as sp

            s = self.system.canonical().at_stop(stop)  # no user name can collide with numpy's or Python's
            x = sp.Matrix(s.states)
            exprs = {
                "f": lambda: sp.Matrix(s.vector_field),
                "h": lambda: s.guard,
                "g": lambda: sp.Matrix(s.reset),
                "f_x": lambda: sp.Matrix(s.vector_field).jacobian(x),
                "h_x": lambda: sp.Matrix([s.guard]).jacobian(x),
                "g_x": lambda: sp.Matrix(s.reset).jacobian(x),
                "h_t": lambda: sp.diff(s.guard, s.time),
                "h_p": lambda: sp.Matrix([s.guard]).jacobian(sp.Matrix(s.params)),
                "g_t": lambda: sp.diff(sp.Matrix(s.reset), s.time),
                "g_p": lambda: sp.Matrix(s.reset).jacobian(sp.Matrix(s.params)),
                "rate": lambda: s.normal_rate,
                "rate_x": lambda: sp.Matrix([s.normal_rate]).jacobian(x),
                "rate_t": lambda: sp.diff(s.normal_rate, s.time),
                "rate_p": lambda: sp.Matrix([s.normal_rate]).jacobian(sp.Matrix(s.params)),
                "accel": lambda: s.normal_accel,
            }
            fn = sp.lambdify(
                (list(s.states), s.time, list(s.params)), exprs[what](), modules="numpy", dummify=True
            )
            self._numeric[what, stop] = fn
        return fn

    def period(self, values: Sequence[float]) -> float:
        """The forcing period for the parameter values ``values``."""
        return float(self._period_fn(*values))


def _transition_layout(symbolic: Mapping[str, Any]) -> list[tuple[str, str, str, Any, Any, Any, int]]:
    """Every transition of a model with modes, in the order of its index ``j``: per mode its stops, then
    the transitions leaving it, then each surface's two.

    Each is ``(name, source, target, guard, reset or None, contact direction or None, sign)``, the guard
    as given (text or sympy) to be multiplied by ``sign``.  Unknown modes are reported later (by name).
    """
    out = []
    names = [md[0] for md in symbolic["modes"]]
    for mode, _, stops in symbolic["modes"]:
        out += [(st[0], mode, mode, st[1], st[2], st[3], 1) for st in stops]
        out += [
            (tr[0], tr[1], tr[2], tr[3], tr[4], tr[5], 1) for tr in symbolic["transitions"] if tr[1] == mode
        ]
    out += [
        (tr[0], tr[1], tr[2], tr[3], tr[4], tr[5], 1) for tr in symbolic["transitions"] if tr[1] not in names
    ]
    for name, h, positive, negative, _ in symbolic["surfaces"]:
        out.append((f"{name}_to_{negative}", positive, negative, h, None, None, 1))
        out.append((f"{name}_to_{positive}", negative, positive, h, None, None, -1))
    return out


def _sliding_layout(symbolic: Mapping[str, Any]) -> tuple[tuple[str, ...], tuple[tuple[str, str, str], ...]]:
    """The sliding pseudo-modes of a model with modes and their virtual transitions, by name.

    Returns the pseudo-modes' names (``"sliding on 'belt'"``, one per surface
    with ``sliding=True``, after the real modes) and per pseudo-mode four
    virtual transitions ``(name, source, target)`` after the real ones: the exits
    to the positive and the negative side, the entries from the positive and
    the negative side (the order of
    :meth:`~grazing.core.symbolic.SymbolicSystem.sliding_modes`).
    """
    names, switches = [], []
    for name, _, positive, negative, sliding in symbolic["surfaces"]:
        if not sliding:
            continue
        mode = f"sliding on {name!r}"
        names.append(mode)
        switches += [
            (f"{name}_exit_to_{positive}", mode, positive),
            (f"{name}_exit_to_{negative}", mode, negative),
            (f"{name}_slide_from_{positive}", positive, mode),
            (f"{name}_slide_from_{negative}", negative, mode),
        ]
    return tuple(names), tuple(switches)


def _modes_system(
    pieces: Mapping[str, Any],
    states: tuple[Any, ...],
    time: Any,
    psyms: tuple[Any, ...],
    period: Any,
    expr: Callable[[Any], Any],
) -> SymbolicSystem:
    """The :class:`SymbolicSystem` of a model with modes, checked (one-line errors)."""
    import sympy as sp

    names = [md[0] for md in pieces["modes"]]
    known = ", ".join(names)
    n = len(states)
    modes = []
    for name, field, _ in pieces["modes"]:
        if len(field) != n:
            raise ValueError(f"the vector field of mode {name!r} needs one expression per state")
        modes.append(Mode(name, tuple(expr(e) for e in field)))
    for name, _, positive, negative, _ in pieces["surfaces"]:
        for side in (positive, negative):
            if side not in names:
                raise ValueError(f"surface {name!r} has unknown mode {side!r} (modes: {known})")
        if positive == negative:
            raise ValueError(f"surface {name!r} needs two different modes, got {positive!r} twice")
    stops, sources, targets, resets = [], [], [], []
    for name, source, target, guard, reset, cd, sign in _transition_layout(pieces):
        for end, mode in (("goes to", target), ("leaves", source)):
            if mode not in names:
                raise ValueError(f"transition {name!r} {end} unknown mode {mode!r} (modes: {known})")
        if reset is not None and len(reset) != n:
            raise ValueError(f"the reset of transition {name!r} needs one expression per state")
        if cd is not None and len(cd) != n:
            raise ValueError(f"the contact_direction of transition {name!r} needs one expression per state")
        if cd is not None and (reset is None or target != source):
            raise ValueError(
                f"the contact_direction of transition {name!r} is for sticking to a stop: it needs a reset "
                f"back to its own mode (a stop of mode {source!r}), not a switch to {target!r}"
            )
        stops.append(Stop(
            name, sign * expr(guard), tuple(states) if reset is None else tuple(expr(e) for e in reset),
            None if cd is None else tuple(expr(e) for e in cd),
        ))  # fmt: skip
        sources.append(names.index(source))
        targets.append(names.index(target))
        resets.append(reset is not None)
    surfaces = tuple(Surface(nm, expr(h), pos, neg, bool(sl)) for nm, h, pos, neg, sl in pieces["surfaces"])
    initial = names.index(pieces["initial_mode"])
    system = SymbolicSystem(
        states=states, time=time, params=psyms, vector_field=modes[initial].vector_field,
        guard=stops[0].guard, reset=stops[0].reset, contact_direction=stops[0].contact_direction,
        period=period, stops=tuple(stops), modes=tuple(modes), sources=tuple(sources),
        targets=tuple(targets), resets=tuple(resets), surfaces=surfaces,
    )  # fmt: skip
    allowed = set(states) | {time} | set(psyms)
    every = [e for md in modes for e in md.vector_field] + [sf.h for sf in surfaces]
    for e in [*every, *(e for st in stops for e in (st.guard, *st.reset, *(st.contact_direction or ())))]:
        extra = e.free_symbols - allowed
        if extra:
            raise ValueError(f"unknown symbols {sorted(map(str, extra))} in {e}")
    if period.free_symbols - set(psyms):
        raise ValueError("the period may depend on parameters only")
    for where, e in _expressions(system):
        check_expression(e, where)
    kind = {False: "transition", True: "stop"}
    for j, st in enumerate(stops):
        what = f"the guard of {kind[sources[j] == targets[j] and resets[j]]} {st.name!r}"
        if not st.guard.free_symbols & (set(states) | {time}):
            raise ValueError(f"{what} depends on neither the state nor time: it can never be crossed")
        if sp.simplify(system.at_stop(j).normal_rate) == 0:
            raise ValueError(
                f"{what} is constant along mode {names[sources[j]]!r}'s flow (L_f h = 0): it can never be "
                "crossed"
            )
    for k, sf in enumerate(surfaces):
        pos, neg = system.surface_sides(k)
        if sf.sliding and sp.simplify(pos.lie(sf.h) - neg.lie(sf.h)) == 0:
            raise ValueError(
                f"surface {sf.name!r} has no sliding region: modes {sf.positive!r} and {sf.negative!r} cross "
                "it alike (L+h - L-h = 0); give sliding=False"
            )
    entered = {initial} | {targets[j] for j in range(len(stops))}
    for k, name in enumerate(names):
        if k not in entered:
            raise ValueError(
                f"mode {name!r} is never entered (no transition leads to it and it is not the initial mode)"
            )
    return system


def _modes_pieces(
    modes: Sequence[Mode],
    transitions: Sequence[Transition],
    surfaces: Sequence[Surface],
    initial_mode: str | None,
) -> dict[str, Any]:
    """The ``symbolic`` entries of a model with modes (plain tuples, hashed into its identity)."""
    if not modes or not all(isinstance(md, Mode) for md in modes):
        raise ValueError("modes must be a non-empty list of grazing.Mode")
    if not all(isinstance(tr, Transition) for tr in transitions):
        raise ValueError("transitions must be a list of grazing.Transition")
    if not all(isinstance(sf, Surface) for sf in surfaces):
        raise ValueError("surfaces must be a list of grazing.Surface")
    for md in modes:
        if not all(isinstance(st, Stop) for st in md.stops):
            raise ValueError(f"the stops of mode {md.name!r} must be a list of grazing.Stop")
    names = [md.name for md in modes]
    for sf in surfaces:
        if sf.positive == sf.negative:
            raise ValueError(f"surface {sf.name!r} needs two different modes, got {sf.positive!r} twice")
    if initial_mode is not None and initial_mode not in names:
        raise ValueError(f"unknown initial mode {initial_mode!r} (modes: {', '.join(map(str, names))})")

    def opt(seq: Sequence[Any] | None) -> tuple[Any, ...] | None:
        return None if seq is None else tuple(seq)

    return {
        "modes": tuple(
            (
                md.name,
                tuple(md.vector_field),
                tuple((st.name, st.guard, tuple(st.reset), opt(st.contact_direction)) for st in md.stops),
            )
            for md in modes
        ),
        "transitions": tuple(
            (tr.name, tr.source, tr.target, tr.guard, opt(tr.reset), opt(tr.contact_direction))
            for tr in transitions
        ),
        "surfaces": tuple((sf.name, sf.h, sf.positive, sf.negative, bool(sf.sliding)) for sf in surfaces),
        "initial_mode": names[0] if initial_mode is None else initial_mode,
    }


def _expressions(system: SymbolicSystem) -> list[tuple[str, Any]]:
    """Every expression of a model with where it is, for messages (``"the guard of stop 'left'"``)."""
    out: list[tuple[str, Any]] = [
        (f"the vector field ({x}')", e) for x, e in zip(system.states, system.vector_field)
    ]
    for md in system.modes:
        out += [
            (f"the vector field of mode {md.name!r} ({x}')", e)
            for x, e in zip(system.states, md.vector_field)
        ]
    out += [(f"the function of surface {sf.name!r}", sf.h) for sf in system.surfaces]
    for st in system.stops:
        of = "" if len(system.stops) == 1 and st.name == "stop" else f" of stop {st.name!r}"
        of = f" of transition {st.name!r}" if system.modes else of
        out += [(f"the guard{of}", st.guard)]
        out += [(f"the reset{of}", e) for e in st.reset]
        out += [(f"the contact direction{of}", e) for e in st.contact_direction or ()]
    out.append(("the period", system.period))
    return out


def _greek(name: str) -> str:
    """``"tau"`` -> ``"τ"``: a symbol spelled as a Greek letter's name, printed as the letter.

    Examples
    --------
    >>> _greek("tau"), _greek("t"), _greek("Omega")
    ('τ', 't', 'Ω')
    """
    import unicodedata

    case = "CAPITAL" if name[:1].isupper() else "SMALL"
    try:
        return unicodedata.lookup(f"GREEK {case} LETTER {name.upper()}")
    except KeyError:
        return name


def _compiled_period(system: SymbolicSystem) -> Callable[..., float]:
    """A plain-Python function of the parameter values for the symbolic period.

    The expression is printed with the parameters renamed ``_p[i]`` and every
    function qualified by its module, so no parameter name can shadow ``pi``,
    ``e`` or a function.
    """
    from sympy.printing.pycode import PythonCodePrinter

    class _Printer(PythonCodePrinter):
        def _print_Symbol(self, sym: Any) -> str:  # noqa: N802 - sympy printer protocol
            return f"_p[{system.params.index(sym)}]"

    text = _Printer({"fully_qualified_modules": True, "standard": "python3"}).doprint(system.period)
    fn = eval(compile(f"lambda *_p: {text}", "<period>", "eval"), {"math": math, "__builtins__": {}})
    return fn  # type: ignore[no-any-return]


def _srepr(obj: Any) -> str:
    if isinstance(obj, (list, tuple)):
        return "(" + ",".join(_srepr(o) for o in obj) + ")"
    if type(obj).__module__.startswith("sympy"):
        import sympy as sp

        return sp.srepr(obj)
    if callable(obj):
        return f"{getattr(obj, '__module__', '')}.{getattr(obj, '__qualname__', repr(obj))}"
    return repr(obj)


_DEFINITIONS: dict[str, _Definition] = {}


@dataclass(frozen=True)
class ParameterTable:
    """Parameter vectors and forcing periods of many points (:meth:`HybridModel.parameter_table`)."""

    vectors: np.ndarray
    """One row per point: every parameter's value in the model's order (:attr:`HybridModel.param_vector`)."""
    periods: np.ndarray
    """Each point's forcing period (as :attr:`HybridModel.period`)."""


def _rebuild(args: dict[str, Any], values: dict[str, float]) -> HybridModel:
    """Unpickle a model: reuse (or build) its definition, then set the values."""
    return HybridModel._from(_Definition.get(args), dict(values))


class HybridModel:
    """A hybrid dynamical system ``x' = f(x, t)``, ``h(x, t) > 0``, ``x <- g(x, t)``.

    Parameters
    ----------
    name
        Short name of the model.
    states
        sympy symbols of the state vector.
    time
        sympy symbol of time.
    parameters
        The model's :class:`Parameter` list; expressions refer to them by
        ``sympy.Symbol(parameter.name)``.
    vector_field
        ``f(x, t)``, one expression per state.
    guard
        ``h(x, t)``: positive in the allowed region, zero on the stop (a
        model with one stop, named ``"stop"``).
    reset
        ``g(x, t)``: the state just after an impact.
    period
        Forcing period (expression in the parameters): stroboscopic samples are
        taken once per period.
    stops
        Several stops instead of ``guard``/``reset``/``contact_direction``: a
        list of :class:`Stop` (name, guard, reset, contact direction).  The
        allowed region is where every guard is positive; on each step the
        earliest root of any guard is the next impact, and of two stops hit at
        the same instant (to rounding) the first in this list is applied.
    contact_direction
        Direction in which the reset acts (for a mechanical impact, the
        velocity direction). Needed to continue complete chattering as
        sticking; without it a chattering accumulation stops the run.
    periodic
        True when f, h and g are periodic in time with the given period (lets
        the engine keep the forcing phase exact over long runs).
    state_labels
        Display names of the states (defaults to the symbol names).
    state_units
        Units of the states, for labels (``"rad"`` marks an angle, shown in
        degrees when a plot asks for degrees); empty by default.
    description
        One line saying what the model is (shown by ``grazing models``).
    reference
        Where the model comes from (a paper, a book), for the reader.
    values
        Parameter values (defaults from ``parameters``).
    modes
        Several vector fields instead of ``vector_field``: a list of
        :class:`Mode` (name, field, the impacts within it as stops).  Their
        stops and then ``transitions`` and ``surfaces`` are the model's
        transitions (:attr:`stop_names`, in that order: per mode its stops and
        the transitions leaving it, then each surface's two).
    transitions
        With ``modes``: switches from one mode to another when a guard
        reaches 0 (:class:`Transition`, with or without a reset).
    surfaces
        With ``modes``: switching surfaces crossed both ways without a reset
        (:class:`Surface`).
    initial_mode
        With ``modes``: the mode a run starts in by default (the first).

    Examples
    --------
    A linear oscillator hitting a stop at ``x = sigma``:

    >>> import sympy as sp
    >>> from grazing import HybridModel, Parameter
    >>> x, v, t = sp.symbols("x v t")
    >>> zeta, w, sigma, r = sp.symbols("zeta omega sigma r")
    >>> model = HybridModel(
    ...     "oscillator", [x, v], t,
    ...     [Parameter("zeta", 0.05, lower=0), Parameter("omega", 1.5, lower=0, lower_open=True),
    ...      Parameter("sigma", 0.5), Parameter("r", 0.8, lower=0, upper=1)],
    ...     vector_field=[v, -2 * zeta * v - x + sp.cos(w * t)],
    ...     guard=sigma - x, reset=[x, -r * v], period=2 * sp.pi / w,
    ...     contact_direction=[0, 1])
    >>> model.with_params(r=0.5).params["r"]
    0.5

    Two stops, one on each side (``stops=`` instead of ``guard``/``reset``):

    >>> from grazing import Stop
    >>> two = HybridModel(
    ...     "two-sided", [x, v], t, [Parameter("omega", 1.5, lower=0, lower_open=True),
    ...     Parameter("r", 0.8, lower=0, upper=1)],
    ...     vector_field=[v, -x + sp.cos(w * t)], period=2 * sp.pi / w,
    ...     stops=[Stop("right", 1 - x, [x, -r * v]), Stop("left", x + 1, [x, -r * v])])
    >>> two.stop_names
    ('right', 'left')

    A compliant stop: a second vector field beyond ``x = sigma``, entered and left without a reset:

    >>> from grazing import Mode, Transition
    >>> soft = HybridModel(
    ...     "soft", [x, v], t, [Parameter("omega", 1.5, lower=0, lower_open=True), Parameter("sigma", 0.5)],
    ...     modes=[Mode("free", [v, -x + sp.cos(w * t)]),
    ...            Mode("contact", [v, -x - 20 * (x - sigma) + sp.cos(w * t)])],
    ...     transitions=[Transition("touch", "free", "contact", sigma - x),
    ...                  Transition("leave", "contact", "free", x - sigma)], period=2 * sp.pi / w)
    >>> soft.mode_names, soft.stop_names, soft.transition_target
    (('free', 'contact'), ('touch', 'leave'), ('contact', 'free'))
    """

    def __init__(
        self,
        name: str,
        states: Sequence[Any],
        time: Any,
        parameters: Sequence[Parameter],
        vector_field: Sequence[Any] | None = None,
        guard: Any = None,
        reset: Sequence[Any] | None = None,
        period: Any = None,
        *,
        stops: Sequence[Stop] | None = None,
        contact_direction: Sequence[Any] | None = None,
        periodic: bool = True,
        state_labels: Sequence[str] | None = None,
        description: str = "",
        reference: str = "",
        values: Mapping[str, float] | None = None,
        state_units: Sequence[str] | None = None,
        modes: Sequence[Mode] | None = None,
        transitions: Sequence[Transition] = (),
        surfaces: Sequence[Surface] = (),
        initial_mode: str | None = None,
    ):
        if period is None:
            raise ValueError("a model needs its forcing period (period=...)")
        symbolic: dict[str, Any] = {"states": tuple(states), "time": time}
        if modes is not None:
            if vector_field is not None:
                raise ValueError("give either vector_field= (one mode) or modes=[...], not both")
            if any(arg is not None for arg in (guard, reset, stops, contact_direction)):
                raise ValueError(
                    "with modes=[...], give each mode's stops in its Mode, not guard=/reset=/stops="
                )
            symbolic.update(_modes_pieces(modes, transitions, surfaces, initial_mode))
        elif vector_field is None:
            raise ValueError("a model needs vector_field= (one mode) or modes=[...]")
        elif transitions or surfaces or initial_mode is not None:
            raise ValueError("transitions=, surfaces= and initial_mode= need modes=[...]")
        else:
            symbolic["vector_field"] = tuple(vector_field)
        if modes is None and stops is not None:
            if guard is not None or reset is not None or contact_direction is not None:
                raise ValueError("give either stops= or guard=/reset=/contact_direction=, not both")
            if not stops or not all(isinstance(st, Stop) for st in stops):
                raise ValueError("stops must be a non-empty list of grazing.Stop")
            symbolic["stops"] = tuple(
                (
                    st.name,
                    st.guard,
                    tuple(st.reset),
                    None if st.contact_direction is None else tuple(st.contact_direction),
                )
                for st in stops
            )
        elif modes is None:
            if guard is None or reset is None:
                raise ValueError("a model needs a guard and a reset (or stops=[...])")
            symbolic["guard"] = guard
            symbolic["reset"] = tuple(reset)
            symbolic["contact_direction"] = None if contact_direction is None else tuple(contact_direction)
        self._def = _Definition.get(
            {
                "name": name,
                "parameters": tuple(parameters),
                "state_names": tuple(str(x) for x in states),
                "period": period,
                "periodic": periodic,
                "state_labels": None if state_labels is None else tuple(state_labels),
                "description": description,
                "reference": reference,
                "symbolic": symbolic,
                "state_units": None if state_units is None else tuple(state_units),
                "time_label": _greek(str(time)),
            }
        )
        self._values = self._checked({p.name: p.default for p in self._def.parameters}, values or {})

    @classmethod
    def lazy(
        cls,
        name: str,
        *,
        parameters: Sequence[Parameter],
        state_names: Sequence[str],
        period: str,
        builder: Callable[[], dict[str, Any]],
        periodic: bool = True,
        state_labels: Sequence[str] | None = None,
        description: str = "",
        reference: str = "",
        state_units: Sequence[str] | None = None,
        time_label: str = "t",
        stop_names: Sequence[str] = ("stop",),
    ) -> HybridModel:
        """A model whose symbolic pieces are built by ``builder()`` only when needed.

        ``builder`` (a module-level function) returns a dict with ``states``,
        ``time``, ``vector_field``, ``guard``, ``reset`` and optionally
        ``contact_direction`` (or ``stops``, a list of :class:`Stop` named
        ``stop_names``); ``period`` is the period as an expression text in
        the parameter names (``"2*pi/omega"``).  The compiled kernels are found
        in the cache by the builder's source text, so a cached model starts
        without importing sympy.  The built-in models are made this way.
        """
        definition = _Definition.get(
            {
                "name": name,
                "parameters": tuple(parameters),
                "state_names": tuple(state_names),
                "period": period,
                "periodic": periodic,
                "state_labels": None if state_labels is None else tuple(state_labels),
                "description": description,
                "reference": reference,
                "builder": builder,
                "state_units": None if state_units is None else tuple(state_units),
                "time_label": time_label,
                "stop_names": tuple(stop_names),
            }
        )
        obj = cls._from(definition, {})
        obj._values = obj._checked({p.name: p.default for p in definition.parameters}, {})
        return obj

    # -- construction -------------------------------------------------------
    @classmethod
    def _from(cls, definition: _Definition, values: dict[str, float]) -> HybridModel:
        obj = cls.__new__(cls)
        obj._def = definition
        obj._values = values
        return obj

    def _checked(self, base: dict[str, float], changes: Mapping[str, Any]) -> dict[str, float]:
        by_name = {p.name: p for p in self._def.parameters}
        out = dict(base)
        for k, v in changes.items():
            if k not in by_name:
                raise InvalidParameterError(
                    f"unknown parameter {k!r} for model {self._def.name!r} (known: {', '.join(by_name)})"
                )
            out[k] = by_name[k].check(v)
        period = self._def.period([out[p.name] for p in self._def.parameters])
        if not (math.isfinite(period) and period > 0):
            raise InvalidParameterError(f"the forcing period must be positive, got {period}")
        return out

    def __reduce__(self) -> tuple[Any, ...]:
        return (_rebuild, (self._def.args, self._values))

    def with_params(self, **changes: float) -> HybridModel:
        """A copy of this model with some parameter values changed (validated)."""
        return HybridModel._from(self._def, self._checked(self._values, changes))

    def parameter_table(self, names: Sequence[str], points: Any) -> ParameterTable:
        """The parameter vectors and forcing periods of ``with_params(**dict(zip(names, point)))`` for
        each row of ``points``, without making a model per point.

        The same numbers (the period by the same function of the same values) and
        the same validation: a point :meth:`with_params` refuses raises its error
        (the first such point's, in order).  Points equal as numbers (0.0 and
        -0.0 too) are one point: the first of them.  A sweep's table of points
        (:class:`grazing.sweeps.run.LaneBatch`) is built so.

        Examples
        --------
        >>> from grazing.models import impact_oscillator
        >>> table = impact_oscillator().parameter_table(["omega"], [[1.0], [2.0], [1.0]])
        >>> table.periods.tolist() == [2 * math.pi, math.pi, 2 * math.pi]
        True
        >>> impact_oscillator(omega=3.0).parameter_table([], [(), ()]).periods.tolist()  # (the model's own)
        [2.0943951023931953, 2.0943951023931953]
        >>> impact_oscillator().parameter_table(["omega"], [[1.0], [-2.0]])
        Traceback (most recent call last):
        ...
        grazing.errors.InvalidParameterError: omega = -2 is outside (0, inf) (forcing frequency)
        """
        pts = np.asarray(points, dtype=float)
        pts = pts.reshape(len(pts), len(names))  # (no names: every point is the model's own)
        params = self._def.parameters
        columns = [[p.name for p in params].index(name) if name in self._values else -1 for name in names]
        admitted = all(k >= 0 and params[k].admits(pts[:, j]).all() for j, k in enumerate(columns))
        if admitted and len(pts):
            if names:
                _, first, inverse = np.unique(pts, axis=0, return_index=True, return_inverse=True)
            else:
                first, inverse = np.zeros(1, dtype=np.int64), np.zeros(len(pts), dtype=np.int64)
            vectors = np.tile(self.param_vector, (len(first), 1))
            vectors[:, columns] = pts[first]
            try:
                distinct = np.array([self._def.period(v) for v in vectors.tolist()], dtype=float)
            except Exception:  # (raised again below, by the point that raises it)
                distinct = np.array([np.nan])
            if np.all(np.isfinite(distinct) & (distinct > 0)):
                return ParameterTable(vectors[inverse.reshape(-1)], distinct[inverse.reshape(-1)])
        models = [self.with_params(**dict(zip(names, pt))) for pt in pts.tolist()]  # (raises the error)
        return ParameterTable(  # pragma: no cover - (every point with_params accepts is accepted above)
            np.array([m.param_vector for m in models]).reshape(len(pts), -1),
            np.array([m.period for m in models], dtype=float),
        )

    # -- description ----------------------------------------------------------
    @property
    def name(self) -> str:
        return self._def.name

    @property
    def parameters(self) -> tuple[Parameter, ...]:
        return self._def.parameters

    @property
    def params(self) -> Mapping[str, float]:
        """Current parameter values (read-only)."""
        return MappingProxyType(self._values)

    @property
    def param_vector(self) -> np.ndarray:
        return np.array([self._values[p.name] for p in self._def.parameters], dtype=float)

    @property
    def state_names(self) -> tuple[str, ...]:
        return self._def.state_names

    @property
    def state_labels(self) -> tuple[str, ...]:
        return self._def.state_labels

    @property
    def state_units(self) -> tuple[str, ...]:
        """Units of the states (for labels; ``""`` when not given)."""
        return self._def.state_units

    @property
    def time_label(self) -> str:
        """How to print time (``"t"``, ``"τ"`` ...)."""
        return self._def.time_label or "t"

    def parameter(self, name: str) -> Parameter:
        """The :class:`Parameter` called ``name``."""
        for p in self._def.parameters:
            if p.name == name:
                return p
        known = ", ".join(p.name for p in self._def.parameters)
        raise InvalidParameterError(f"unknown parameter {name!r} for model {self.name!r} (known: {known})")

    def stop_level(self, component: int, t: float = 0.0, stop: int | str | None = None) -> float | None:
        """The value of state ``component`` on a stop (the first by default) whose guard depends on it alone.

        For a stop at ``x_c = c`` (a guard affine in ``x_c``, independent of the
        other states and of time, as the pendulum's ``theta_hat - theta``) this
        is ``c``; otherwise None.  Found numerically from the compiled guard
        (two evaluations, checked at three random states and times), for
        drawing the stop in plots.
        """
        n, j = self.n_states, self.stop_index(stop)
        x0 = np.zeros(n)
        unit = np.zeros(n)
        unit[component] = 1.0
        h0 = self.guard(x0, t, j)
        slope = self.guard(unit, t, j) - h0
        if slope == 0.0 or not math.isfinite(slope):
            return None
        rng = np.random.default_rng(0)
        for _ in range(3):
            x = rng.normal(size=n)
            tt = float(rng.uniform(0.0, self.period))
            expected = h0 + slope * x[component]
            if abs(self.guard(x, tt, j) - expected) > 1e-9 * (1.0 + abs(h0) + abs(slope * x[component])):
                return None
        return -h0 / slope

    @property
    def n_states(self) -> int:
        return len(self._def.state_names)

    @property
    def stop_names(self) -> tuple[str, ...]:
        """The names of the model's stops (``("stop",)`` for a model given by one guard)."""
        return self._def.stop_names

    @property
    def n_stops(self) -> int:
        return len(self._def.stop_names)

    def stop_index(self, stop: int | str | None) -> int:
        """The index of a stop given by name or index (None: the first).

        Examples
        --------
        >>> from grazing.models import two_sided_oscillator
        >>> two_sided_oscillator().stop_index("left")
        1
        """
        if stop is None:
            return 0
        if isinstance(stop, str):
            if stop in self._def.stop_names:
                return self._def.stop_names.index(stop)
            known = ", ".join(self._def.stop_names)
            raise InvalidParameterError(f"unknown stop {stop!r} for model {self.name!r} (stops: {known})")
        if isinstance(stop, (int, np.integer)) and not isinstance(stop, bool) and 0 <= stop < self.n_stops:
            return int(stop)
        raise InvalidParameterError(
            f"stop must be a stop name or an index below {self.n_stops}, got {stop!r}"
        )

    @property
    def mode_names(self) -> tuple[str, ...]:
        """The names of the model's modes (``("free",)`` for a model of one vector field), then its sliding
        pseudo-modes (``"sliding on 'belt'"``, :attr:`sliding_modes`)."""
        return self._def.mode_names

    @property
    def n_modes(self) -> int:
        return len(self._def.mode_names)

    @property
    def surface_names(self) -> tuple[str, ...]:
        """The names of the model's switching surfaces (:class:`Surface`; empty without any)."""
        return self._def.surface_names

    @property
    def sliding_modes(self) -> dict[int, int]:
        """The sliding pseudo-modes: each one's mode index (into :attr:`mode_names`) to its surface's index.

        A surface with ``sliding=True`` has a pseudo-mode ``"sliding on 'name'"``
        after the real modes: the motion on the surface, along Filippov's
        convex combination of the two sides' fields.
        """
        sliding = self._def.sliding_surfaces
        first = len(self.mode_names) - len(sliding)
        return {first + k: i for k, i in enumerate(sliding)}

    @property
    def sliding_names(self) -> tuple[str, ...]:
        """The names of the sliding pseudo-modes (the last of :attr:`mode_names`)."""
        return tuple(self.mode_names[k] for k in self.sliding_modes)

    @property
    def switch_names(self) -> tuple[str, ...]:
        """Every transition a switch may be on: :attr:`stop_names`, then the sliding pseudo-modes' exits
        and entries (``belt_exit_to_slip``, ``belt_slide_from_slip``; see :attr:`sliding_modes`)."""
        return self.stop_names + tuple(sw[0] for sw in self._def.sliding_switches)

    @property
    def switch_sources(self) -> tuple[str, ...]:
        """The mode each of :attr:`switch_names` leaves."""
        return self.transition_source + tuple(sw[1] for sw in self._def.sliding_switches)

    @property
    def switch_targets(self) -> tuple[str, ...]:
        """The mode each of :attr:`switch_names` enters."""
        return self.transition_target + tuple(sw[2] for sw in self._def.sliding_switches)

    @property
    def has_modes(self) -> bool:
        """True for a model given with ``modes=[...]`` (its stops are all its transitions)."""
        return self._def.transition_modes is not None

    @property
    def initial_mode(self) -> str:
        """The mode a run starts in unless told otherwise."""
        symbolic = self._def._symbolic
        return symbolic["initial_mode"] if self.has_modes and symbolic is not None else self.mode_names[0]

    @property
    def transition_source(self) -> tuple[str, ...]:
        """The mode each transition (each of :attr:`stop_names`) leaves."""
        modes = self._def.transition_modes
        return tuple(src for src, _ in modes) if modes is not None else self.mode_names * self.n_stops

    @property
    def transition_target(self) -> tuple[str, ...]:
        """The mode each transition (each of :attr:`stop_names`) enters."""
        modes = self._def.transition_modes
        return tuple(tgt for _, tgt in modes) if modes is not None else self.mode_names * self.n_stops

    @property
    def transition_resets(self) -> tuple[bool, ...]:
        """Whether each transition (each of :attr:`stop_names`) resets the state (an impact); a switch of
        vector field does not.  A model without modes: every stop resets.

        Examples
        --------
        >>> import grazing
        >>> grazing.models.soft_impact_oscillator().transition_resets
        (False, False)
        """
        resets = self._def.transition_resets
        return resets if resets is not None else (True,) * self.n_stops

    def mode_index(self, mode: str | None) -> int:
        """The index of a mode given by name (None: the initial mode).

        Examples
        --------
        >>> from grazing.models import impact_oscillator
        >>> impact_oscillator().mode_index(None)
        0
        """
        name = self.initial_mode if mode is None else mode
        real = self.mode_names[: len(self.mode_names) - len(self.sliding_modes)]
        if name not in real:
            known = ", ".join(real)
            if name in self.mode_names:
                raise InvalidParameterError(
                    f"a run cannot start in mode {name!r} of model {self.name!r}: start on the surface in "
                    f"either side's mode (modes: {known}); it slides from there"
                )
            raise InvalidParameterError(f"unknown mode {name!r} for model {self.name!r} (modes: {known})")
        return self.mode_names.index(name)

    def mode_at(self, x: Any, t: float = 0.0) -> str:
        """The mode a state ``x`` at time ``t`` lies in: the first (the initial mode first) whose outgoing
        transitions' guards are all >= 0 there (to :data:`ON_STOP_TOL`, as :meth:`check_state` allows).

        A model without modes: its one mode.  A state in no mode's region raises a one-line
        :class:`~grazing.errors.InvalidStateError`.

        Examples
        --------
        >>> import grazing
        >>> m = grazing.models.soft_impact_oscillator()
        >>> m.mode_at([0.0, 0.0]), m.mode_at([m.params["gap"] + 0.1, 0.0])
        ('free', 'contact')
        """
        arr = self.check_state(x, t, allowed=False)
        if not self.has_modes:
            return self.mode_names[0]
        k = mode_of_states(self, arr[None], float(t))[0]
        if k < 0:
            raise InvalidStateError(f"state {arr.tolist()} is in no mode of model {self.name!r} (every mode "
                                    "has a transition whose guard is negative there)")  # fmt: skip
        return self.mode_names[int(k)]

    def start_mode(self, x: Any, t: float = 0.0, mode: str | None = None, *, resets: bool = True) -> str:
        """The mode a run from ``x`` at time ``t`` starts in: ``mode`` where given; else the initial mode
        where ``x`` lies in its region (on its edge too: :meth:`check_state`, with ``resets`` as there), else
        the one other mode whose region it lies in (an absorbing mode, which no transition leaves and whose
        region is everywhere, only where no other's is): :meth:`mode_at`'s answer, which the basins use.

        Raises a one-line :class:`~grazing.errors.InvalidStateError` where that is ambiguous (``x``
        outside the initial mode's region on a switching surface between two others: give ``mode``) or
        where ``x`` is in no mode's region.  A model without modes: its one mode.

        Examples
        --------
        >>> import grazing
        >>> m = grazing.models.rocking_block()
        >>> m.start_mode([0.1, 0.0]), m.start_mode([-0.1, 0.0]), m.start_mode([0.0, -1.0])
        ('right_corner', 'left_corner', 'right_corner')
        >>> m.start_mode([2.0, 0.0]), m.start_mode([0.1, 0.0], mode="overturned")
        ('overturned', 'overturned')
        """
        if mode is not None or not self.has_modes:
            return self.mode_names[self.mode_index(mode)]
        try:
            arr = self.check_state(x, t, resets=resets)
        except InvalidStateError:
            arr = self.check_state(x, t, allowed=False)
        else:
            return self.initial_mode
        inside = mode_regions(self, arr[None], float(t))[0]
        absorbing = absorbing_modes(self)
        order = _mode_order(self)[1:]
        for group in ([k for k in order if self.mode_names[k] not in absorbing], order):
            found = [self.mode_names[k] for k in group if inside[k]]
            if len(found) > 1:
                names = ", ".join(map(repr, found))
                raise InvalidStateError(
                    f"state {arr.tolist()} lies in the regions of modes {names} of model {self.name!r} (not "
                    f"in the initial mode {self.initial_mode!r}'s): say which mode it starts in"
                )
            if found:
                return found[0]
        return self.mode_at(arr, t)  # (in none: its one-line error)

    def require_one_mode(self, what: str) -> None:
        """Raise a one-line error if this model has several modes: ``what`` does not support them yet."""
        if self.has_modes:
            raise InvalidParameterError(
                f"{what} does not support models with modes yet (model {self.name!r} has modes "
                f"{', '.join(self.mode_names)})"
            )

    @property
    def period(self) -> float:
        """Forcing period (the stroboscopic sampling interval)."""
        return self._def.period(self.param_vector)

    @property
    def periodic(self) -> bool:
        return self._def.periodic

    @property
    def has_sticking(self) -> bool:
        """True when some stop has a contact direction (chattering on it continues as sticking)."""
        return any(st.contact_direction is not None for st in self._def.system.stops)

    @property
    def symbolic(self) -> SymbolicSystem:
        """The symbolic vector field, guard and reset."""
        return self._def.system

    @property
    def description(self) -> str:
        return self._def.description

    @property
    def reference(self) -> str:
        return self._def.reference

    def __repr__(self) -> str:
        vals = ", ".join(f"{k}={v:g}" for k, v in self._values.items())
        return f"<HybridModel {self.name}: {vals}>"

    # -- numerics -------------------------------------------------------------
    def kernels(self, directions: int = 0, order: int | None = None) -> Any:
        """The compiled kernel module (generated and cached on first use).

        One module per number of sensitivity ``directions`` (columns of the
        variational matrix holding parameter derivatives along directions
        given at run time; see
        :func:`~grazing.engine.codegen.direction_columns`) and Taylor
        ``order``; the model's scalar functions (vector field, guard, reset and
        their derivatives) are in every module.
        """
        if isinstance(directions, bool) or not isinstance(directions, int) or directions < 0:
            raise InvalidParameterError(f"directions must be a non-negative integer, got {directions!r}")
        return self._def.kernels(directions, None if order is None else int(order))

    def numeric(self, what: str, stop: int | str | None = None) -> Callable[..., Any]:
        """The model's ``what`` as a numpy function of ``(x, t, p)``, straight from sympy.

        ``what`` is one of ``f``, ``h``, ``g``, ``f_x``, ``h_x``, ``g_x``,
        ``h_t``, ``h_p``, ``g_t``, ``rate``, ``rate_x``, ``rate_t``,
        ``rate_p``, ``accel``, of stop ``stop`` (name or index; the first by
        default).  These are ``sympy.lambdify`` functions, slow but
        independent of the compiled kernels: for checks and references.

        Examples
        --------
        >>> from grazing.models import impact_oscillator
        >>> m = impact_oscillator(sigma=0.1)
        >>> float(m.numeric("h")([0.0, 1.0], 0.0, list(m.param_vector)))
        0.1
        """
        return self._def.numeric(what, self.stop_index(stop))

    def _call(self, what: str, x: Any, t: float, stop: int = 0) -> Any:
        fn = self._def.numeric(what, stop)
        return fn(list(np.asarray(x, dtype=float)), float(t), list(self.param_vector))

    def vector_field(self, x: Any, t: float = 0.0, mode: str | None = None) -> np.ndarray:
        """``f(x, t)`` of ``mode`` (the initial mode by default; a sliding pseudo-mode's is Filippov's field;
        evaluated by the compiled kernels)."""
        out = np.empty(self.n_states)
        x = np.ascontiguousarray(x, dtype=float)
        if self.has_modes:
            k = self.mode_names.index(mode) if mode in self.sliding_names else self.mode_index(mode)
            self._def.scalar_kernels().rhs(x, float(t), self.param_vector, out, k)
        else:
            self.mode_index(mode)  # (only the one mode's name)
            self._def.scalar_kernels().rhs(x, float(t), self.param_vector, out)
        return out

    def guard(self, x: Any, t: float = 0.0, stop: int | str | None = None) -> float:
        """``h(x, t)`` of a stop (the first by default): positive in the allowed region."""
        j = self.stop_index(stop)
        return float(
            self._def.scalar_kernels().guard(
                np.ascontiguousarray(x, dtype=float), float(t), self.param_vector, j
            )
        )

    def guards(self, x: Any, t: float = 0.0) -> np.ndarray:
        """Every stop's guard at ``(x, t)``, in the order of :attr:`stop_names`."""
        return np.array([self.guard(x, t, j) for j in range(self.n_stops)])

    def reset(self, x: Any, t: float = 0.0, stop: int | str | None = None) -> np.ndarray:
        """``g(x, t)`` of a stop: the state just after an impact at ``x``."""
        out = np.empty(self.n_states)
        j = self.stop_index(stop)
        self._def.scalar_kernels().reset(
            np.ascontiguousarray(x, dtype=float), float(t), self.param_vector, out, j
        )
        return out

    def normal_accel(self, x: Any, t: float = 0.0, stop: int | str | None = None) -> float:
        """``L_f^2 h`` at ``(x, t)``: a guard's acceleration along the flow (compiled)."""
        j = self.stop_index(stop)
        return float(
            self._def.scalar_kernels().normal_accel(
                np.ascontiguousarray(x, dtype=float), float(t), self.param_vector, j
            )
        )

    def jacobians(
        self, x: Any, t: float = 0.0, stop: int | str | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(f_x, h_x, g_x)`` at ``(x, t)`` for a stop."""
        n, j = self.n_states, self.stop_index(stop)
        fx = np.asarray(self._call("f_x", x, t, j if self.has_modes else 0), dtype=float).reshape(n, n)
        hx = np.asarray(self._call("h_x", x, t, j), dtype=float).reshape(n)
        gx = np.asarray(self._call("g_x", x, t, j), dtype=float).reshape(n, n)
        return fx, hx, gx

    def saltation(self, x: Any, t: float = 0.0, stop: int | str | None = None) -> np.ndarray:
        """Saltation matrix (paper eq. 14) of an impact at ``x`` on the stop.

        ``S = g_x + (f(g(x)) - g_x f(x) - g_t) h_x / (h_x f(x) + h_t)``; the
        time terms vanish for autonomous guards and resets, giving eq. 14.  In
        a model with modes ``stop`` is any transition, ``f(x)`` its source
        mode's field and ``f(g(x))`` its target's (a switch without a reset:
        ``S = I + (f+ - f-) h_x / (h_x f- + h_t)``).
        """
        j = self.stop_index(stop)
        _, hx, gx = self.jacobians(x, t, j)
        source, target = self.transition_source[j], self.transition_target[j]
        fm = self.vector_field(x, t, source if self.has_modes else None)
        fp = self.vector_field(self.reset(x, t, j), t, target if self.has_modes else None)
        gt = np.asarray(self._call("g_t", x, t, j), dtype=float).reshape(-1)
        ht = float(self._call("h_t", x, t, j))
        return gx + np.outer(fp - gx @ fm - gt, hx) / (hx @ fm + ht)

    def contact_derivatives(self, x: Any, t: float = 0.0, stop: int | str | None = None) -> dict[str, Any]:
        """A stop's guard ``h`` and its rate ``L_f h`` with their derivatives at ``(x, t)``.

        Keys: ``h, h_x, h_t, h_p, rate, rate_x, rate_t, rate_p, accel`` (``accel``
        is ``L_f^2 h``); ``_p`` derivatives are with respect to every parameter,
        in the order of :attr:`parameters`.  These define grazing: ``h = 0`` and
        ``L_f h = 0`` with ``L_f^2 h > 0``.
        """
        n, m, j = self.n_states, len(self.parameters), self.stop_index(stop)
        return {
            "h": self.guard(x, t, j),
            "h_x": np.asarray(self._call("h_x", x, t, j), dtype=float).reshape(n),
            "h_t": float(self._call("h_t", x, t, j)),
            "h_p": np.asarray(self._call("h_p", x, t, j), dtype=float).reshape(m),
            "rate": float(self._call("rate", x, t, j)),
            "rate_x": np.asarray(self._call("rate_x", x, t, j), dtype=float).reshape(n),
            "rate_t": float(self._call("rate_t", x, t, j)),
            "rate_p": np.asarray(self._call("rate_p", x, t, j), dtype=float).reshape(m),
            "accel": float(self._call("accel", x, t, j)),
        }

    def check_state(
        self, x: Any, t: float = 0.0, allowed: bool = True, mode: str | None = None, *, resets: bool = True
    ) -> np.ndarray:
        """Return ``x`` as a float array, or raise if it is not a valid state.

        With ``allowed`` (the default) the state must also satisfy the guard (to
        :data:`ON_STOP_TOL`: a state on the stop to rounding is allowed); in a
        model with modes, the guards of the transitions that leave ``mode``
        (the initial mode by default), those with a reset only if ``resets``
        (a run without events passes through them, not through the others).
        """
        arr = np.asarray(x, dtype=float).reshape(-1)
        if arr.shape != (self.n_states,):
            raise InvalidStateError(
                f"state must have {self.n_states} components ({', '.join(self.state_names)}), got {arr.size}"
            )
        if not np.all(np.isfinite(arr)):
            raise InvalidStateError(f"state must be finite, got {arr.tolist()}")
        if not allowed:
            return arr
        k = self.mode_index(mode)
        for j, name in enumerate(self.stop_names):
            if self.has_modes and self.transition_source[j] != self.mode_names[k]:
                continue
            if not (resets or not self.transition_resets[j]):
                continue
            hv = self.guard(arr, t, j)
            if hv < -ON_STOP_TOL * max(1.0, float(np.max(np.abs(arr)))):
                if self.has_modes and self.transition_target[j] != self.mode_names[k]:
                    raise InvalidStateError(
                        f"initial state {arr.tolist()} is not in mode {self.mode_names[k]!r} (guard of "
                        f"transition {name!r} h = {hv:.3g} < 0)"
                    )
                where = "the stop" if name == "stop" else f"stop {name!r}"
                raise InvalidStateError(
                    f"initial state {arr.tolist()} is beyond {where} (guard h = {hv:.3g} < 0)"
                )
        return arr


def mode_of_states(model: HybridModel, states: np.ndarray, t: float) -> np.ndarray:
    """The index of the mode each row of ``states`` lies in at time ``t`` (:meth:`HybridModel.mode_at`),
    -1 where none: the first mode (the initial one first, the absorbing ones, without a transition out,
    last: their region is everywhere) whose outgoing transitions' guards are all above
    ``-ON_STOP_TOL * max(1, |x|)``.

    Examples
    --------
    >>> import grazing
    >>> m = grazing.models.soft_impact_oscillator(gap=0.5)
    >>> mode_of_states(m, np.array([[0.0, 1.0], [0.7, 0.0], [0.5, 0.0]]), 0.0).tolist()
    [0, 1, 0]
    """
    inside = mode_regions(model, states, t)
    out = np.full(inside.shape[0], -1, dtype=np.int64)
    for k in _mode_order(model):
        out[(out < 0) & inside[:, k]] = k
    return out


def mode_regions(model: HybridModel, states: np.ndarray, t: float) -> np.ndarray:
    """Whether each row of ``states`` lies in the region of each mode (a run can start in; not the sliding
    pseudo-modes) at time ``t``: ``(rows, modes)``, the guards of the mode's outgoing transitions all above
    ``-ON_STOP_TOL * max(1, |x|)`` (an absorbing mode, without one: everywhere).  A model without modes:
    its one mode, inside every stop.

    Examples
    --------
    >>> import grazing
    >>> m = grazing.models.rocking_block()
    >>> mode_regions(m, np.array([[0.1, 0.0], [0.0, 0.0], [2.0, 0.0]]), 0.0).tolist()
    [[True, False, True], [True, True, True], [False, False, True]]
    """
    x = np.asarray(states, dtype=float)
    real = model.mode_names[: len(model.mode_names) - len(model.sliding_modes)]
    inside = np.ones((x.shape[0], len(real)), dtype=bool)
    if x.shape[0] == 0:
        return inside
    params = list(model.param_vector)
    scale = np.maximum(1.0, np.max(np.abs(x), axis=1))
    columns = [x[:, c] for c in range(x.shape[1])]
    for j in range(model.n_stops):
        k = real.index(model.transition_source[j]) if model.has_modes else 0
        h = np.broadcast_to(
            np.asarray(model.numeric("h", j)(columns, float(t), params), dtype=float), scale.shape
        )
        inside[:, k] &= h >= -ON_STOP_TOL * scale
    return inside


def absorbing_modes(model: HybridModel) -> tuple[str, ...]:
    """The modes (not the sliding pseudo-modes) that no transition leaves: a motion that enters one ends
    there (the rocking block's ``overturned``).  Their region is everywhere.

    Examples
    --------
    >>> import grazing
    >>> absorbing_modes(grazing.models.rocking_block()), absorbing_modes(grazing.models.pendulum())
    (('overturned',), ())
    """
    if not model.has_modes:
        return ()
    real = model.mode_names[: len(model.mode_names) - len(model.sliding_modes)]
    return tuple(m for m in real if m not in model.transition_source)


def _mode_order(model: HybridModel) -> list[int]:
    """The order in which a state's mode is looked for: the initial mode, the others, the absorbing ones."""
    real = model.mode_names[: len(model.mode_names) - len(model.sliding_modes)]
    first, absorbing = model.mode_index(None), absorbing_modes(model)
    rest = [i for i in range(len(real)) if i != first]
    return [first] + [i for i in rest if real[i] not in absorbing] + [i for i in rest if real[i] in absorbing]


def in_modes(model: HybridModel, states: np.ndarray, modes: np.ndarray, t: float) -> np.ndarray:
    """Whether each row of ``states`` lies in the region of its mode ``modes`` (indices) at time ``t``: the
    guards of the mode's outgoing transitions all above ``-ON_STOP_TOL * max(1, |x|)``, as
    :func:`mode_of_states` decides.  A model without modes: not beyond a stop.

    Examples
    --------
    >>> import grazing
    >>> m = grazing.models.soft_impact_oscillator(gap=0.5)
    >>> in_modes(m, np.array([[0.0, 1.0], [0.0, 1.0], [0.7, 0.0]]), np.array([0, 1, 0]), 0.0).tolist()
    [True, False, False]
    """
    inside = mode_regions(model, states, t)
    n = inside.shape[0]
    which = np.asarray(modes, dtype=np.int64) if model.has_modes else np.zeros(n, dtype=np.int64)
    out = np.ones(n, dtype=bool)  # (a mode not known, -1, or a sliding pseudo-mode: no guard of its own)
    known = np.flatnonzero((which >= 0) & (which < inside.shape[1]))
    out[known] = inside[known, which[known]]
    return out
