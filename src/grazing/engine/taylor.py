"""Code generation of Taylor-coefficient kernels from symbolic vector fields.

Taylor's method advances ``x' = F(x, t)`` by computing the normalised Taylor
coefficients ``x[k] = x^(k)(t0) / k!`` of the solution to a high order ``p``
by automatic differentiation: the right-hand side is decomposed into
elementary operations (sums, products, quotients, ``sin``/``cos`` and
``sinh``/``cosh`` pairs, ``tan`` and ``tanh`` with their derivative's series
``1 +- t^2``, ``exp``, ``log``, powers with any exponent, and the functions
``F`` expanded through their derivative ``F'(u) u'``: ``asin``, ``acos``,
``atan``, ``asinh``, ``acosh``, ``atanh``, ``erf``, ``erfc``), each with a
recurrence that gives its ``k``-th coefficient from lower ones (Jorba & Zou
2005; Biscani & Izzo 2021, the heyoka paper).  Which functions a model may
use is decided in one place, :mod:`grazing.core.expressions`, when the model
is built.  This module turns a sympy vector field into the Python source
of one numba function that runs those recurrences; the engine compiles it
once per model and order and caches it on disk.

As in heyoka, the kernel is generated for a fixed order and fully unrolled:
every coefficient of every sub-expression is a scalar local variable, every
convolution sum is written out term by term (as a balanced tree of additions,
so that the processor can overlap them), and terms that are zero by
construction are left out at generation time.  Compared with loops over
coefficient arrays this is 2-3 times faster.

Every sub-expression is classified at generation time as

* constant within a step (depends on parameters and numbers only): one scalar,
  computed once per call;
* affine in time (``a*t + b`` with constant ``a``, ``b``): two scalars, so that
  forcing terms such as ``sin(omega*t)`` cost O(1) per order instead of O(k);
* general: one scalar per order.

Extra *output* expressions (event functions such as the guard) are expanded
to the same order as the state, so the engine sees them as polynomials in the
step time.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from grazing.core.expressions import RECIPROCALS, smooth_form, unsupported
from grazing.errors import UnsupportedExpressionError

__all__ = ["ScalarPrinter", "TaylorKernel", "UnsupportedExpressionError", "taylor_kernel"]


_INVERSES: dict[str, Callable[[sp.Expr], sp.Expr]] = {
    "asin": lambda u: 1 / sp.sqrt((1 - u) * (1 + u)),
    "acos": lambda u: -1 / sp.sqrt((1 - u) * (1 + u)),
    "atan": lambda u: 1 / (1 + u**2),
    "asinh": lambda u: 1 / sp.sqrt(1 + u**2),
    "acosh": lambda u: 1 / sp.sqrt((u - 1) * (u + 1)),
    "atanh": lambda u: 1 / ((1 - u) * (1 + u)),
    "erf": lambda u: 2 / sp.sqrt(sp.pi) * sp.exp(-(u**2)),
    "erfc": lambda u: -2 / sp.sqrt(sp.pi) * sp.exp(-(u**2)),
}
"""Functions ``F`` expanded through their derivative ``F'(u)``, a smooth expression of ``u``:
``(F o u)' = F'(u) u'``.  (``1 - u^2`` is written ``(1 - u)(1 + u)``: accurate near ``|u| = 1``.)"""


@dataclass(frozen=True)
class _Const:
    name: str


@dataclass(frozen=True)
class _Affine:
    v0: str  # value at the start of the step
    v1: str  # slope d/dt (constant)


@dataclass(frozen=True)
class _General:
    name: str  # coefficient k is the local variable ``{name}_{k}`` of the generated code


_Ref = _Const | _Affine | _General
_Emitter = Callable[[int], list[str]]


def _sum(terms: Sequence[str]) -> str:
    """Sum of ``terms`` as a balanced tree of additions (short dependency chains)."""
    if not terms:
        return "0.0"
    if len(terms) == 1:
        return terms[0]
    mid = len(terms) // 2
    return f"({_sum(terms[:mid])} + {_sum(terms[mid:])})"


def _inv(k: int) -> str:
    """The literal ``1/k``."""
    return repr(1.0 / k)


def _div_by(expr: str, k: int) -> str:
    """``expr / k`` as a multiplication by the literal ``1/k`` (nothing for ``k = 1``)."""
    return expr if k == 1 else f"{expr} * {_inv(k)}"


class ScalarPrinter(PythonCodePrinter):
    """Prints constant sub-expressions as plain ``math`` scalar code."""

    def __init__(self, names: dict[sp.Symbol, str]):
        super().__init__({"fully_qualified_modules": True, "standard": "python3"})
        self._names = names

    def _print_Symbol(self, expr):  # noqa: N802 - sympy printer protocol
        if expr not in self._names:  # every symbol is named by the generator: never print a user's name
            raise ValueError(f"internal error: no code name for the symbol {expr!r}")
        return self._names[expr]

    def _print_Dummy(self, expr):  # noqa: N802
        return self._print_Symbol(expr)

    def _print_Rational(self, expr):  # noqa: N802
        return f"({float(expr.p)!r}/{float(expr.q)!r})"

    def _print_Integer(self, expr):  # noqa: N802
        return repr(float(expr))

    def _print_Float(self, expr):  # noqa: N802
        return repr(float(expr))

    def _print_Pow(self, expr, rational=False):  # noqa: N802
        # Small integer powers as products: x**-2.0 would cost a call to pow.
        e = expr.exp
        if e.is_Integer and 1 <= abs(int(e)) <= 4:
            prod = " * ".join([f"({self._print(expr.base)})"] * abs(int(e)))
            return f"({prod})" if e > 0 else f"(1.0 / ({prod}))"
        return super()._print_Pow(expr, rational=rational)


@dataclass
class _Builder:
    states: tuple[sp.Symbol, ...]
    time: sp.Symbol
    param_names: dict[sp.Symbol, str]
    prologue: list[str] = field(default_factory=list)
    nodes: list[tuple[str, _Emitter, set[str]]] = field(default_factory=list)
    # (name, code assigning coefficient k, names of the nodes it depends on)
    memo: dict[sp.Expr, _Ref] = field(default_factory=dict)
    trig: dict[sp.Expr, tuple[str, str]] = field(default_factory=dict)
    hyperbolic: dict[sp.Expr, tuple[str, str]] = field(default_factory=dict)
    n_scalar: int = 0
    n_node: int = 0

    def __post_init__(self) -> None:
        self.state_index = {s: i for i, s in enumerate(self.states)}
        self.printer = ScalarPrinter(self.param_names)

    # -- naming ---------------------------------------------------------
    def _scalar(self, code: str) -> str:
        name = f"c{self.n_scalar}"
        self.n_scalar += 1
        self.prologue.append(f"{name} = {code}")
        return name

    def _name(self) -> str:
        name = f"w{self.n_node}"
        self.n_node += 1
        return name

    def _node(self, emit: _Emitter, *refs: _Ref) -> _General:
        name = self._name()
        self.nodes.append((name, lambda k: [f"{name}_{k} = {emit(k)[0]}"], self.deps(*refs)))
        return _General(name)

    # -- classification -------------------------------------------------
    def _is_constant(self, expr: sp.Expr) -> bool:
        syms = expr.free_symbols
        return self.time not in syms and not any(s in self.state_index for s in syms)

    @staticmethod
    def term(ref: _Ref, k: int) -> str | None:
        """Code for the ``k``-th Taylor coefficient of ``ref``; None where it is zero."""
        if isinstance(ref, _General):
            return f"{ref.name}_{k}"
        if isinstance(ref, _Const):
            return ref.name if k == 0 else None
        return ref.v0 if k == 0 else (ref.v1 if k == 1 else None)

    @classmethod
    def coef(cls, ref: _Ref, k: int) -> str:
        """Like :meth:`term`, with ``0.0`` for the zero coefficients."""
        return cls.term(ref, k) or "0.0"

    @classmethod
    def products(cls, a: _Ref, b: _Ref, k: int, lo: int = 0) -> list[str]:
        """Nonzero terms ``a_j * b_(k-j)`` for ``j = lo .. k``."""
        out = []
        for j in range(lo, k + 1):
            ta, tb = cls.term(a, j), cls.term(b, k - j)
            if ta is not None and tb is not None:
                out.append(f"{ta} * {tb}")
        return out

    @classmethod
    def weighted(cls, u: _Ref, prefix: str) -> tuple[_Emitter, _Ref]:
        """The series ``j * u_j`` (the time derivative of ``u`` times t): code and reference.

        The returned emitter defines coefficient ``k`` as ``{prefix}_{k}``;
        the reference names it so that :meth:`products` can use it.
        """

        def emit(k: int) -> list[str]:
            t = cls.term(u, k)
            if k == 0 or t is None:
                return []
            return [f"{prefix}_{k} = {t}" if k == 1 else f"{prefix}_{k} = {float(k)!r} * {t}"]

        if isinstance(u, _Affine):  # j * u_j is v1 at j = 1, zero elsewhere
            return (lambda k: []), _Affine("0.0", u.v1)
        return emit, _General(prefix)

    @staticmethod
    def deps(*refs: _Ref) -> set[str]:
        return {r.name for r in refs if isinstance(r, _General)}

    # -- expression visitor -----------------------------------------------
    def visit(self, expr: sp.Expr) -> _Ref:
        expr = sp.sympify(expr)
        if expr in self.memo:
            return self.memo[expr]
        if self._is_constant(expr):
            ref: _Ref = _Const(self._scalar(self.printer.doprint(expr)))
        elif expr == self.time:
            ref = _Affine("s0", "1.0")
        elif expr in self.state_index:
            ref = _General(f"xs{self.state_index[expr]}")
        elif isinstance(expr, sp.Add):
            ref = self._add([self.visit(a) for a in expr.args])
        elif isinstance(expr, sp.Mul):
            ref = self._mul_expr(expr)
        elif isinstance(expr, sp.Pow):
            ref = self._pow(expr.base, expr.exp)
        elif isinstance(expr, (sp.sin, sp.cos)):
            s, c = self._sincos(expr.args[0])
            ref = _General(s if isinstance(expr, sp.sin) else c)
        elif isinstance(expr, (sp.sinh, sp.cosh)):
            s, c = self._sinhcosh(expr.args[0])
            ref = _General(s if isinstance(expr, sp.sinh) else c)
        elif isinstance(expr, (sp.tan, sp.tanh)):
            ref = self._tan(expr.args[0], hyperbolic=isinstance(expr, sp.tanh))
        elif isinstance(expr, sp.exp):
            ref = self._exp(self.visit(expr.args[0]))
        elif isinstance(expr, sp.log):
            ref = self._log(self.visit(expr.args[0]))
        elif type(expr).__name__ in _INVERSES:
            ref = self._through_derivative(type(expr).__name__, expr.args[0])
        elif type(expr).__name__ in RECIPROCALS:  # sec(u) = 1/cos(u) ... (the canonical system has none)
            ref = self.visit(smooth_form(expr))
        else:
            # HybridModel refuses these when it is built; this is for direct callers.
            raise UnsupportedExpressionError(unsupported(expr, "the expression") or f"cannot expand {expr}")
        self.memo[expr] = ref
        return ref

    # -- operations -------------------------------------------------------
    def _add(self, refs: Sequence[_Ref]) -> _Ref:
        consts = [r.name for r in refs if isinstance(r, _Const)]
        affs = [r for r in refs if isinstance(r, _Affine)]
        gens = [r for r in refs if isinstance(r, _General)]
        c0 = " + ".join(consts + [a.v0 for a in affs]) or "0.0"
        c1 = " + ".join(a.v1 for a in affs) or "0.0"
        if not gens:
            return _Affine(self._scalar(c0), self._scalar(c1))
        v0 = self._scalar(c0) if (consts or affs) else None
        v1 = self._scalar(c1) if affs else None

        def emit(k: int) -> list[str]:
            extra = [v for v, kk in ((v0, 0), (v1, 1)) if v is not None and k == kk]
            return [_sum([f"{g.name}_{k}" for g in gens] + extra)]

        return self._node(emit, *gens)

    def _scale(self, ref: _Ref, c: str) -> _Ref:
        if isinstance(ref, _Const):
            return _Const(self._scalar(f"{c} * {ref.name}"))
        if isinstance(ref, _Affine):
            return _Affine(self._scalar(f"{c} * {ref.v0}"), self._scalar(f"{c} * {ref.v1}"))
        return self._node(lambda k: [f"{c} * {ref.name}_{k}"], ref)

    def _mul(self, a: _Ref, b: _Ref) -> _Ref:
        if isinstance(a, _Const):
            return self._scale(b, a.name)
        if isinstance(b, _Const):
            return self._scale(a, b.name)
        return self._node(lambda k: [_sum(self.products(a, b, k))], a, b)

    def _product(self, refs: Sequence[_Ref]) -> _Ref:
        consts = [r.name for r in refs if isinstance(r, _Const)]
        others = [r for r in refs if not isinstance(r, _Const)]
        if not others:
            return _Const(self._scalar(" * ".join(consts) or "1.0"))
        acc = others[0]
        for r in others[1:]:
            acc = self._mul(acc, r)
        if consts:
            acc = self._scale(acc, self._scalar(" * ".join(consts)))
        return acc

    def _div(self, num: _Ref, den: _Ref) -> _Ref:
        if isinstance(den, _Const):
            return self._scale(num, self._scalar(f"1.0 / {den.name}"))
        name = self._name()
        q = _General(name)
        d0 = self.term(den, 0)

        def emit(k: int) -> list[str]:
            lines = [f"{name}_inv = 1.0 / {d0}"] if k == 0 else []
            rest = _sum(self.products(den, q, k, lo=1))
            lines.append(f"{name}_{k} = ({self.coef(num, k)} - {rest}) * {name}_inv")
            return lines

        self.nodes.append((name, emit, self.deps(num, den)))
        return q

    def _mul_expr(self, expr: sp.Mul) -> _Ref:
        num, den = [], []
        for f in expr.args:
            if isinstance(f, sp.Pow) and f.exp.is_number and f.exp.is_negative and not self._is_constant(f):
                den.append(self.visit(f.base if f.exp == -1 else sp.Pow(f.base, -f.exp)))
            else:
                num.append(self.visit(f))
        if not den:
            return self._product(num)
        return self._div(self._product(num), self._product(den))

    def _pow(self, base: sp.Expr, exponent: sp.Expr) -> _Ref:
        if not self._is_constant(exponent):  # b**e = exp(e log b) (heyoka's decomposition)
            return self._exp(self._mul(self.visit(exponent), self.visit(sp.log(base))))
        b = self.visit(base)
        if exponent.is_Integer:
            n = int(exponent)
            if n == 0:
                return _Const(self._scalar("1.0"))
            if n < 0:
                return self._div(_Const(self._scalar("1.0")), self._pow(base, -exponent))
            if n <= 16:
                # Binary exponentiation with product nodes (no division by u[0]).
                result: _Ref | None = None
                square = b
                while n:
                    if n & 1:
                        result = square if result is None else self._mul(result, square)
                    n >>= 1
                    if n:
                        square = self._mul(square, square)
                assert result is not None
                return result
        e = self.visit(exponent)
        assert isinstance(e, _Const)
        name = self._name()
        b0 = self.term(b, 0)

        def emit(k: int) -> list[str]:
            if k == 0:
                return [f"{name}_0 = {b0} ** {e.name}", f"{name}_inv = 1.0 / {b0}"]
            terms = []
            for j in range(k):
                tb = self.term(b, k - j)
                if tb is not None:
                    terms.append(f"({e.name} * {float(k - j)!r} - {float(j)!r}) * {tb} * {name}_{j}")
            return [f"{name}_{k} = {_sum(terms)} * ({_inv(k)} * {name}_inv)"]

        self.nodes.append((name, emit, self.deps(b)))
        return _General(name)

    def _sincos(self, arg: sp.Expr) -> tuple[str, str]:
        """``sin`` and ``cos`` of ``arg`` as a pair: ``s' = c u'``, ``c' = -s u'``."""
        return self._pair(arg, self.trig, ("math.sin", "math.cos"), "-")

    def _sinhcosh(self, arg: sp.Expr) -> tuple[str, str]:
        """``sinh`` and ``cosh`` of ``arg`` as a pair: ``s' = c u'``, ``c' = s u'``."""
        return self._pair(arg, self.hyperbolic, ("math.sinh", "math.cosh"), "")

    def _pair(
        self, arg: sp.Expr, known: dict[sp.Expr, tuple[str, str]], functions: tuple[str, str], sign: str
    ) -> tuple[str, str]:
        """Two functions of ``arg`` whose derivatives are each other's: ``s' = c u'``, ``c' = sign s u'``."""
        if arg in known:
            return known[arg]
        u = self.visit(arg)
        if isinstance(u, _Const):  # pragma: no cover - constant arguments are folded by visit
            raise AssertionError("constant argument")
        s, c = self._name(), self._name()
        S, C = _General(s), _General(c)
        u0 = self.term(u, 0)
        emit_du, du = self.weighted(u, f"{s}_du")
        f_s, f_c = functions

        def emit(k: int) -> list[str]:
            if k == 0:
                return [f"{s}_0 = {f_s}({u0})", f"{c}_0 = {f_c}({u0})"]
            return [
                *emit_du(k),
                f"{s}_{k} = {_div_by(_sum(self.products(du, C, k, lo=1)), k)}",
                f"{c}_{k} = {sign}{_div_by(_sum(self.products(du, S, k, lo=1)), k)}",
            ]

        # One node computes both; the second is registered as an alias with no
        # code of its own that depends on the first node.
        self.nodes.append((s, emit, self.deps(u)))
        self.nodes.append((c, lambda k: [], {s}))
        known[arg] = (s, c)
        return s, c

    @classmethod
    def square(cls, ref: _General, k: int) -> str:
        """Coefficient ``k`` of ``ref**2``: ``sum_j ref_j ref_(k-j)``, each cross term once, doubled."""
        pairs = [f"{ref.name}_{j} * {ref.name}_{k - j}" for j in range((k + 1) // 2)]
        parts = [f"2.0 * {_sum(pairs)}"] if pairs else []
        if k % 2 == 0:
            parts.append(f"{ref.name}_{k // 2} * {ref.name}_{k // 2}")
        return " + ".join(parts)

    def _tan(self, arg: sp.Expr, hyperbolic: bool) -> _Ref:
        """``tan`` (``tanh``) of ``arg``: ``t' = q u'`` with ``q = 1 + t^2`` (``1 - t^2``).

        ``q`` is the node's second series; its value ``1 - tanh(u)^2`` is computed as
        ``1 / cosh(u)^2``, accurate where ``tanh(u)`` rounds to 1.
        """
        u = self.visit(arg)
        name = self._name()
        t, q = _General(name), _General(f"{name}_q")
        u0 = self.term(u, 0)
        emit_du, du = self.weighted(u, f"{name}_du")

        def emit(k: int) -> list[str]:
            if k == 0:
                if hyperbolic:
                    return [
                        f"{name}_0 = math.tanh({u0})",
                        f"{name}_ch = math.cosh({u0})",
                        f"{q.name}_0 = 1.0 / ({name}_ch * {name}_ch)",
                    ]
                return [f"{name}_0 = math.tan({u0})", f"{q.name}_0 = 1.0 + {name}_0 * {name}_0"]
            sq = self.square(t, k)
            return [
                *emit_du(k),
                f"{name}_{k} = {_div_by(_sum(self.products(du, q, k, lo=1)), k)}",
                f"{q.name}_{k} = -({sq})" if hyperbolic else f"{q.name}_{k} = {sq}",
            ]

        self.nodes.append((name, emit, self.deps(u)))
        return t

    def _through_derivative(self, function: str, arg: sp.Expr) -> _Ref:
        """``F(arg)`` for ``F`` in :data:`_INVERSES`: ``a_0 = F(u_0)``, ``a_k = (1/k) sum_j j u_j g_(k-j)``.

        ``g = F'(u)`` is expanded as an expression of ``arg`` (sharing its
        sub-expressions with the rest of the kernel).
        """
        u = self.visit(arg)
        g = self.visit(_INVERSES[function](arg))
        name = self._name()
        u0 = self.term(u, 0)
        emit_du, du = self.weighted(u, f"{name}_du")

        def emit(k: int) -> list[str]:
            if k == 0:
                return [f"{name}_0 = math.{function}({u0})"]
            return [*emit_du(k), f"{name}_{k} = {_div_by(_sum(self.products(du, g, k, lo=1)), k)}"]

        self.nodes.append((name, emit, self.deps(u, g)))
        return _General(name)

    def _exp(self, u: _Ref) -> _Ref:
        name = self._name()
        p = _General(name)
        u0 = self.term(u, 0)
        emit_du, du = self.weighted(u, f"{name}_du")

        def emit(k: int) -> list[str]:
            if k == 0:
                return [f"{name}_0 = math.exp({u0})"]
            return [*emit_du(k), f"{name}_{k} = {_div_by(_sum(self.products(du, p, k, lo=1)), k)}"]

        self.nodes.append((name, emit, self.deps(u)))
        return p

    def _log(self, u: _Ref) -> _Ref:
        name = self._name()
        p = _General(name)
        u0 = self.term(u, 0)

        def emit(k: int) -> list[str]:
            if k == 0:
                return [f"{name}_0 = math.log({u0})", f"{name}_inv = 1.0 / {u0}"]
            rest = [f"{float(j)!r} * {name}_{j} * {t}" for j in range(1, k) if (t := self.term(u, k - j))]
            uk = self.term(u, k)
            lead = f"{float(k)!r} * {uk}" if uk is not None else "0.0"
            return [f"{name}_{k} = ({lead} - {_sum(rest)}) * ({_inv(k)} * {name}_inv)"]

        self.nodes.append((name, emit, self.deps(u)))
        return p


def _cone(nodes: list[tuple[str, _Emitter, set[str]]], roots: set[str]) -> set[str]:
    """Names of the nodes that the nodes ``roots`` depend on (inclusive)."""
    deps = {name: d for name, _, d in nodes}
    seen: set[str] = set()
    stack = [r for r in roots if r in deps]
    while stack:
        n = stack.pop()
        if n in seen:
            continue
        seen.add(n)
        stack.extend(d for d in deps[n] if d in deps)
    return seen


@dataclass(frozen=True)
class TaylorKernel:
    """Source of a generated Taylor kernel and the sizes its caller must allocate."""

    name: str
    source: str
    n_states: int
    n_outputs: int
    order: int


def taylor_kernel(
    name: str,
    states: Sequence[sp.Symbol],
    time: sp.Symbol,
    params: Sequence[sp.Symbol],
    rhs: Sequence[sp.Expr],
    outputs: Sequence[sp.Expr] = (),
    order: int = 20,
) -> TaylorKernel:
    """Generate ``name(x0, s0, pv, X, O)`` for Taylor polynomials of degree ``order``.

    The generated function writes the normalised Taylor coefficients of the
    solution of ``states' = rhs`` through ``x0`` at time ``s0`` into
    ``X[i, 0..order]`` and those of each output expression into
    ``O[m, 0..order]``.  ``pv`` holds the parameter values in the order of
    ``params``.

    Examples
    --------
    >>> import sympy as sp
    >>> x, t, w = sp.symbols("x t w")
    >>> k = taylor_kernel("tc", [x], t, [w], [sp.cos(w * t)], outputs=[x - 1], order=3)
    >>> (k.n_states, k.n_outputs, k.order)
    (1, 1, 3)
    >>> print(next(ln for ln in k.source.splitlines() if "xs0_2 =" in ln).strip())
    xs0_2 = w1_1 * 0.5
    """
    states = tuple(states)
    if len(rhs) != len(states):
        raise ValueError("rhs must have one expression per state")
    if order < 1:
        raise ValueError("order must be at least 1")
    names = {p: f"p{i}" for i, p in enumerate(params)}
    b = _Builder(states, time, names)
    rhs_refs = [b.visit(e) for e in rhs]
    out_refs = [b.visit(e) for e in outputs]
    cone = _cone(b.nodes, b.deps(*out_refs))

    ind = "    "
    src = [f"def {name}(x0, s0, pv, X, O):"]
    for p_, pname in names.items():
        src.append(f"{ind}{pname} = pv[{params.index(p_)}]")
    src += [ind + ln for ln in b.prologue]
    for i in range(len(states)):
        src.append(f"{ind}xs{i}_0 = x0[{i}]")
    for k in range(order + 1):
        for node, emit, _ in b.nodes:
            if k < order or node in cone:
                src += [ind + ln for ln in emit(k)]
        if k < order:
            for i, ref in enumerate(rhs_refs):
                t = b.term(ref, k)
                src.append(f"{ind}xs{i}_{k + 1} = {_div_by(t, k + 1) if t else '0.0'}")
    for i in range(len(states)):
        src += [f"{ind}X[{i}, {k}] = xs{i}_{k}" for k in range(order + 1)]
    for m, ref in enumerate(out_refs):
        src += [f"{ind}O[{m}, {k}] = {b.coef(ref, k)}" for k in range(order + 1)]
    src.append(f"{ind}return")
    return TaylorKernel(
        name=name,
        source="\n".join(src) + "\n",
        n_states=len(states),
        n_outputs=len(out_refs),
        order=order,
    )
