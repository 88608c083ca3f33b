"""Code generation of Taylor-coefficient kernels from symbolic vector fields.

Taylor's method advances ``x' = F(x, t)`` by computing the normalised Taylor
coefficients ``x[k] = x^(k)(t0) / k!`` of the solution to a high order ``p``
by automatic differentiation: the right-hand side is decomposed into
elementary operations (sums, products, quotients, ``sin``/``cos`` pairs,
``exp``, ``log``, powers), each with a recurrence that gives its ``k``-th
coefficient from lower ones (Jorba & Zou 2005; Biscani & Izzo 2021, the
heyoka paper).  This module turns a sympy vector field into the Python source
of one numba function that runs those recurrences; the engine compiles it
once per model and caches it on disk.

Every sub-expression is classified at generation time as

* constant within a step (depends on parameters and numbers only): one scalar,
  computed once per call;
* affine in time (``a*t + b`` with constant ``a``, ``b``): two scalars, so that
  forcing terms such as ``sin(omega*t)`` cost O(1) per order instead of O(k);
* general: an array of coefficients.

Extra *output* expressions (event functions such as the guard) are expanded
to the same order as the state, so the engine sees them as polynomials in the
step time.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter


class UnsupportedExpressionError(ValueError):
    """A vector field uses a function the Taylor code generator cannot expand."""


@dataclass(frozen=True)
class _Const:
    name: str


@dataclass(frozen=True)
class _Affine:
    v0: str  # value at the start of the step
    v1: str  # slope d/dt (constant)


@dataclass(frozen=True)
class _General:
    name: str  # name of the coefficient array in the generated code


_Ref = _Const | _Affine | _General


class ScalarPrinter(PythonCodePrinter):
    """Prints constant sub-expressions as plain ``math`` scalar code."""

    def __init__(self, names: dict[sp.Symbol, str]):
        super().__init__({"fully_qualified_modules": True, "standard": "python3"})
        self._names = names

    def _print_Symbol(self, expr):  # noqa: N802 - sympy printer protocol
        return self._names.get(expr, super()._print_Symbol(expr))

    def _print_Rational(self, expr):  # noqa: N802
        return f"({float(expr.p)!r}/{float(expr.q)!r})"

    def _print_Integer(self, expr):  # noqa: N802
        return repr(float(expr))

    def _print_Float(self, expr):  # noqa: N802
        return repr(float(expr))


@dataclass
class _Builder:
    states: tuple[sp.Symbol, ...]
    time: sp.Symbol
    param_names: dict[sp.Symbol, str]
    prologue: list[str] = field(default_factory=list)
    nodes: list[tuple[str, list[str], set[str]]] = field(default_factory=list)
    # (array name, code lines using `k`, names of arrays it depends on)
    memo: dict[sp.Expr, _Ref] = field(default_factory=dict)
    trig: dict[sp.Expr, tuple[str, str]] = field(default_factory=dict)
    n_scalar: int = 0
    n_array: int = 0

    def __post_init__(self) -> None:
        self.state_index = {s: i for i, s in enumerate(self.states)}
        self.printer = ScalarPrinter(self.param_names)

    # -- naming ---------------------------------------------------------
    def _scalar(self, code: str) -> str:
        name = f"c{self.n_scalar}"
        self.n_scalar += 1
        self.prologue.append(f"{name} = {code}")
        return name

    def _array(self) -> str:
        name = f"w{self.n_array}"
        self.n_array += 1
        return name

    def _node(self, lines: list[str], deps: set[str]) -> _General:
        name = self._array()
        self.nodes.append((name, [ln.replace("@", name) for ln in lines], deps))
        return _General(name)

    # -- classification -------------------------------------------------
    def _is_constant(self, expr: sp.Expr) -> bool:
        syms = expr.free_symbols
        return self.time not in syms and not any(s in self.state_index for s in syms)

    @staticmethod
    def coef(ref: _Ref, k: str) -> str:
        """Code for the ``k``-th Taylor coefficient of ``ref``."""
        if isinstance(ref, _General):
            return f"{ref.name}[{k}]"
        if isinstance(ref, _Const):
            return f"({ref.name} if {k} == 0 else 0.0)"
        return f"({ref.v0} if {k} == 0 else ({ref.v1} if {k} == 1 else 0.0))"

    @staticmethod
    def deps(*refs: _Ref) -> set[str]:
        return {r.name for r in refs if isinstance(r, _General)}

    def materialize(self, ref: _Ref) -> _General:
        if isinstance(ref, _General):
            return ref
        return self._node([f"@[k] = {self.coef(ref, 'k')}"], set())

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
        elif isinstance(expr, sp.exp):
            ref = self._exp(self.visit(expr.args[0]))
        elif isinstance(expr, sp.log):
            ref = self._log(self.visit(expr.args[0]))
        else:
            raise UnsupportedExpressionError(
                f"cannot build a Taylor kernel for {type(expr).__name__} in {expr}; "
                "supported: +, *, /, powers with constant exponent, sin, cos, exp, log"
            )
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
        lines = [f"acc = {' + '.join(g.name + '[k]' for g in gens)}"]
        if v0 is not None:
            lines.append(f"if k == 0: acc += {v0}")
        if v1 is not None:
            lines.append(f"if k == 1: acc += {v1}")
        lines.append("@[k] = acc")
        return self._node(lines, self.deps(*gens))

    def _scale(self, ref: _Ref, c: str) -> _Ref:
        if isinstance(ref, _Const):
            return _Const(self._scalar(f"{c} * {ref.name}"))
        if isinstance(ref, _Affine):
            return _Affine(self._scalar(f"{c} * {ref.v0}"), self._scalar(f"{c} * {ref.v1}"))
        return self._node([f"@[k] = {c} * {ref.name}[k]"], {ref.name})

    def _mul(self, a: _Ref, b: _Ref) -> _Ref:
        if isinstance(a, _Const):
            return self._scale(b, a.name)
        if isinstance(b, _Const):
            return self._scale(a, b.name)
        if isinstance(a, _General) and isinstance(b, _Affine):
            a, b = b, a
        if isinstance(a, _Affine) and isinstance(b, _General):
            lines = [
                f"acc = {a.v0} * {b.name}[k]",
                f"if k >= 1: acc += {a.v1} * {b.name}[k - 1]",
                "@[k] = acc",
            ]
            return self._node(lines, {b.name})
        ga, gb = self.materialize(a), self.materialize(b)
        lines = [
            "acc = 0.0",
            "for j in range(k + 1):",
            f"    acc += {ga.name}[j] * {gb.name}[k - j]",
            "@[k] = acc",
        ]
        return self._node(lines, {ga.name, gb.name})

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
        u = self.coef(num, "k")
        if isinstance(den, _Affine):
            lines = [
                f"acc = {u}",
                f"if k >= 1: acc -= {den.v1} * @[k - 1]",
                f"@[k] = acc / {den.v0}",
            ]
            return self._node(lines, self.deps(num))
        lines = [
            f"acc = {u}",
            "for j in range(1, k + 1):",
            f"    acc -= {den.name}[j] * @[k - j]",
            f"@[k] = acc / {den.name}[0]",
        ]
        return self._node(lines, self.deps(num) | {den.name})

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
        if not self._is_constant(exponent):
            raise UnsupportedExpressionError(f"exponent {exponent} depends on the state or time")
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
        g = self.materialize(b)
        lines = [
            "if k == 0:",
            f"    @[0] = {g.name}[0] ** {e.name}",
            "else:",
            "    acc = 0.0",
            "    for j in range(k):",
            f"        acc += ({e.name} * (k - j) - j) * {g.name}[k - j] * @[j]",
            f"    @[k] = acc / (k * {g.name}[0])",
        ]
        return self._node(lines, {g.name})

    def _sincos(self, arg: sp.Expr) -> tuple[str, str]:
        if arg in self.trig:
            return self.trig[arg]
        u = self.visit(arg)
        s, c = self._array(), self._array()
        if isinstance(u, _Affine):
            lines = [
                "if k == 0:",
                f"    {s}[0] = math.sin({u.v0})",
                f"    {c}[0] = math.cos({u.v0})",
                "else:",
                f"    {s}[k] = {u.v1} / k * {c}[k - 1]",
                f"    {c}[k] = -{u.v1} / k * {s}[k - 1]",
            ]
            deps: set[str] = set()
        else:
            assert isinstance(u, _General)
            lines = [
                "if k == 0:",
                f"    {s}[0] = math.sin({u.name}[0])",
                f"    {c}[0] = math.cos({u.name}[0])",
                "else:",
                "    acc_s = 0.0",
                "    acc_c = 0.0",
                "    for j in range(1, k + 1):",
                f"        tj = j * {u.name}[j]",
                f"        acc_s += tj * {c}[k - j]",
                f"        acc_c += tj * {s}[k - j]",
                f"    {s}[k] = acc_s / k",
                f"    {c}[k] = -acc_c / k",
            ]
            deps = {u.name}
        # One node computes both arrays; the cosine array is registered as an
        # alias whose code is empty but which depends on the sine node.
        self.nodes.append((s, lines, deps))
        self.nodes.append((c, [], {s}))
        self.trig[arg] = (s, c)
        return s, c

    def _exp(self, u: _Ref) -> _Ref:
        if isinstance(u, _Affine):
            lines = [
                "if k == 0:",
                f"    @[0] = math.exp({u.v0})",
                "else:",
                f"    @[k] = {u.v1} / k * @[k - 1]",
            ]
            return self._node(lines, set())
        g = self.materialize(u)
        lines = [
            "if k == 0:",
            f"    @[0] = math.exp({g.name}[0])",
            "else:",
            "    acc = 0.0",
            "    for j in range(1, k + 1):",
            f"        acc += j * {g.name}[j] * @[k - j]",
            "    @[k] = acc / k",
        ]
        return self._node(lines, {g.name})

    def _log(self, u: _Ref) -> _Ref:
        g = self.materialize(u)
        lines = [
            "if k == 0:",
            f"    @[0] = math.log({g.name}[0])",
            "else:",
            "    acc = k * " + g.name + "[k]",
            "    for j in range(1, k):",
            f"        acc -= j * @[j] * {g.name}[k - j]",
            f"    @[k] = acc / (k * {g.name}[0])",
        ]
        return self._node(lines, {g.name})


def _cone(nodes: list[tuple[str, list[str], set[str]]], roots: set[str]) -> set[str]:
    """Names of the nodes that the arrays ``roots`` depend on (inclusive)."""
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
    n_work: int


def taylor_kernel(
    name: str,
    states: Sequence[sp.Symbol],
    time: sp.Symbol,
    params: Sequence[sp.Symbol],
    rhs: Sequence[sp.Expr],
    outputs: Sequence[sp.Expr] = (),
) -> TaylorKernel:
    """Generate ``name(x0, s0, pv, order, X, O, W)``.

    The generated function writes the normalised Taylor coefficients of the
    solution of ``states' = rhs`` through ``x0`` at time ``s0`` into
    ``X[i, 0..order]`` and those of each output expression into
    ``O[m, 0..order]``.  ``pv`` holds the parameter values in the order of
    ``params``; ``W`` is a work array of shape ``(n_work, order + 1)``.

    Examples
    --------
    >>> import sympy as sp
    >>> x, t, w = sp.symbols("x t w")
    >>> k = taylor_kernel("tc", [x], t, [w], [sp.cos(w * t)], outputs=[x - 1])
    >>> (k.n_states, k.n_outputs)
    (1, 1)
    """
    states = tuple(states)
    if len(rhs) != len(states):
        raise ValueError("rhs must have one expression per state")
    names = {p: f"p{i}" for i, p in enumerate(params)}
    b = _Builder(states, time, names)
    rhs_refs = [b.visit(e) for e in rhs]
    out_refs = [b.visit(e) for e in outputs]

    out_arrays = {r.name for r in out_refs if isinstance(r, _General) and not r.name.startswith("xs")}
    cone = _cone(b.nodes, out_arrays)

    ind = "    "
    src = [f"def {name}(x0, s0, pv, order, X, O, W):"]
    for p_, pname in names.items():
        src.append(f"{ind}{pname} = pv[{params.index(p_)}]")
    src += [ind + ln for ln in b.prologue]
    for i in range(len(states)):
        src.append(f"{ind}xs{i} = X[{i}]")
        src.append(f"{ind}xs{i}[0] = x0[{i}]")
    for j in range(b.n_array):
        src.append(f"{ind}w{j} = W[{j}]")
    src.append(f"{ind}for k in range(order + 1):")
    src.append(f"{ind * 2}if k < order:")
    for _, lines, _ in b.nodes:
        src += [ind * 3 + ln for ln in lines]
    for i, ref in enumerate(rhs_refs):
        src.append(f"{ind * 3}xs{i}[k + 1] = {b.coef(ref, 'k')} / (k + 1)")
    src.append(f"{ind * 2}else:")
    body = [ind * 3 + ln for n_, lines, _ in b.nodes if n_ in cone for ln in lines]
    src += body or [ind * 3 + "pass"]
    for m, ref in enumerate(out_refs):
        src.append(f"{ind}for k in range(order + 1):")
        src.append(f"{ind * 2}O[{m}, k] = {b.coef(ref, 'k')}")
    src.append(f"{ind}return")
    return TaylorKernel(
        name=name,
        source="\n".join(src) + "\n",
        n_states=len(states),
        n_outputs=len(out_refs),
        n_work=max(b.n_array, 1),
    )
