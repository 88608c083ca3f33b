"""Periodic orbits as a boundary-value problem with one segment per impact (multiple shooting).

Single shooting solves ``P^n(x) - x = 0`` over the whole period: where the
monodromy is large (a saddle flow between impacts, a saltation matrix's
``1 / v`` as an impact speed ``v`` falls to zero: multipliers of ``1e7``) the
map amplifies rounding by as much, its residual cannot fall below
``|M| eps |x|`` and Newton's method stalls short of its tolerance.  Here the
orbit with ``k`` impacts (on stops ``j_1 ... j_k``, in order) is ``k + 1``
segments of free flight, each its own initial-value problem:

* unknowns: the state ``s_0`` on the section ``t0``; for each impact its time
  ``t_i`` and the state ``s_i`` just after it; and the parameter ``p``;
* equations: for each impact, the guard ``h_{j_i}(y_{i-1}, t_i) = 0`` at the
  segment's end ``y_{i-1} = phi(s_{i-1}, t_{i-1} -> t_i)`` and the reset
  ``s_i - g_{j_i}(y_{i-1}, t_i) = 0``; and the return ``phi(s_k, t_k -> t0 + n T) - s_0 = 0``.

The residual of each equation is a segment's, rounded as a segment is, so
Newton's method reaches its tolerance however large the product of the
segments is; the Jacobian is block-sparse (each segment's ``Phi``, its start
and end times' ``-Phi f`` and ``f``, the guards' and resets' derivatives) and
carries no ``1 / v`` (the impact time is an unknown, the guard an equation), so
the equations stay regular through a grazing, where ``v`` passes through zero.
This is the formulation of COCO's ``hspo`` toolbox (a segment per mode, event
times as unknowns, the event and reset as boundary conditions; Dankowicz &
Schilder, *Recipes for Continuation*, SIAM 2013, ch. 4), with the segments
between the impacts of one mode.  The segments are integrated with the stops
ignored: a segment that passes through a stop (it would have hit it) is found
from its guard minimum, so a branch can tell where its impact sequence ends.

The orbit's monodromy is the product of the segments' ``Phi`` and the saltation
matrices (its multipliers are the same as single shooting's); the payload of
each point is a :class:`~grazing.orbits.shooting.PeriodicOrbit`.

On a model with modes the impacts are its transitions with a reset (a same-mode
impact or one that changes the mode, as the rocking block's); each segment
starts in a mode (the section's, then each impact's target mode) and is run
without events (``events=False``), which ignores the resets only: within a
segment the motion switches its vector field and slides as it does in a
simulation, and the segment's ``Phi`` carries those switches' saltation matrices
(the engine's).  A segment must end in the source mode of the impact that ends
it, and the last in the section's mode.  Whether a segment passes through a
reset's guard is told by the same run with the resets watched (the engine keeps
no guard minima through modes).

A model with modes none of whose transitions has a reset (a soft stop, a spring-damper contact) has
no impact to cut at: its segments end on its switches instead (:func:`cuts_at_switches`,
``SegmentLayout.switches``), each segment one mode from the previous switch's surface to the next
switch's guard, as ``hspo``'s.  The equations are the same with the identity for the reset
(continuity ``s_i - y_{i-1} = 0``), the guard row ``h_{j_i}(y_{i-1}, t_i) = 0`` and the monodromy
through the switches' saltation matrices; where rounding lets a segment's run cross its switch just
before its end, the run's own saltation stands in for the end's.  Sliding is not cut at: a run that
slides keeps the layout of its impacts (none: one segment).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.solution import Solution
from grazing.engine.simulate import simulate
from grazing.engine.timebase import SNAP, start_times
from grazing.errors import ConvergenceError, InvalidStateError, SimulationError
from grazing.orbits.periodic import PeriodicOrbit, sorted_multipliers

GRAZING_SPEED_RATIO = 1e-3
"""``find_orbit`` does not solve the segments of a guess's run one of whose impacts is slower than this
fraction of its fastest: that impact is at a grazing (the run from a guess taken just past it touches
the stop at 7e-5 where the orbit's other impact has 1.5), and the segments would keep it as an impact
of zero speed where single shooting finds the orbit without it."""

MULTIPLE_SHOOTING_NORM = 1e4
"""Single shooting hands over to multiple shooting where the monodromy's 2-norm exceeds this (its
residual's rounding, ``|M| eps |x|``, is then within a factor 1e3 of ``core.options.NEWTON_TOL``)."""


@dataclass(frozen=True)
class SegmentFlow:
    """One segment's free flight from ``(x, ta)`` to ``tb``: the end state and its derivatives.

    Attributes
    ----------
    end
        ``phi(x, ta -> tb)``.
    jacobian
        ``d end / d x``.
    sensitivity
        ``d end / d p`` with ``ta`` and ``tb`` held fixed (a parameter that sets the forcing period
        moves neither): a vector for one parameter, a matrix with a column per parameter for several.
    solution
        The run (its guard minima tell whether the segment passes through a stop).
    """

    end: np.ndarray
    jacobian: np.ndarray
    sensitivity: np.ndarray
    solution: Solution


def _segment_span(model: HybridModel, ta: float, tb: float) -> tuple[int, float]:
    """The periods and the sampling phase of a run from ``ta`` whose last sample is at ``tb``."""
    T = model.period
    s_phase = tb % T
    if s_phase >= T * (1.0 - 1e-12):
        s_phase = 0.0
    kb = round((tb - s_phase) / T)
    _, _, ks, _ = start_times(ta, T, s_phase, True)  # (the engine's first sample, as it finds it)
    periods = kb - ks + 1
    if periods < 1 or tb - ta < SNAP * T:
        raise ConvergenceError(f"a segment of the orbit has no length (from t = {ta:.12g} to {tb:.12g})")
    return periods, 2 * math.pi * s_phase / T


def segment_flow(
    model: HybridModel, x: np.ndarray, ta: float, tb: float, param: str | tuple[str, ...] | None,
    mode: str | None = None, touching: int | None = None,
) -> SegmentFlow:  # fmt: skip
    """Free flight (the stops ignored) from state ``x`` at time ``ta`` to time ``tb > ta``.

    ``param``: the parameter (or a tuple of them) whose sensitivities are computed (None: none).
    ``touching``: a transition whose guard the segment starts or ends on tangentially (a grazing
    contact, :attr:`SegmentLayout.contact`), which is no switch there.
    The engine samples at a forcing phase: the run's last sample is the phase of
    ``tb`` after as many periods as it takes to reach it.  On a model with modes
    the segment starts in ``mode`` (the initial mode by default) and ignores the
    transitions with a reset only: it switches and slides on the way (its
    solution's ``mode_final`` and ``switches``), its Jacobian through the
    switches' saltation matrices.

    Examples
    --------
    >>> import math, grazing
    >>> m = grazing.models.impact_oscillator()
    >>> T = m.period
    >>> a = segment_flow(m, np.array([0.1, 0.2]), 0.3, 0.3 + 1.7 * T, "omega")
    >>> b = grazing.simulate(m, [0.1, 0.2], t0=0.3, periods=2, phase=2 * math.pi * ((0.3 + 1.7 * T) / T % 1),
    ...                      events=False).x_final
    >>> bool(np.allclose(a.end, b, atol=1e-13)), a.jacobian.shape, a.sensitivity.shape
    (True, (2, 2), (2,))
    """
    T = model.period
    periods, phase = _segment_span(model, ta, tb)
    names = () if param is None else (param,) if isinstance(param, str) else tuple(param)
    sol = simulate(
        model, x, t0=ta, periods=periods, phase=phase, jacobian=True, sensitivities=names,
        guard_min=not model.has_modes, events=False, impacts="all" if model.has_modes else "none",
        mode=mode, **({} if touching is None else {"touching": True, "stop_name": touching}),
    )  # fmt: skip
    n = model.n_states
    end = sol.x_final
    if not names:
        return SegmentFlow(end, sol.jacobian[:, :n], np.zeros(n), sol)
    columns = []
    for i, name in enumerate(names):
        sens = sol.jacobian[:, n + i]
        tp = sol.info["period_gradient"][name]
        if tp:  # (the engine's end (kb + s_phase/T) T(p) moves with T; the segment's end tb does not)
            sens = sens - model.vector_field(end, sol.t_final, sol.mode_final) * (sol.t_final / T) * tp
        columns.append(sens)
    sensitivity = columns[0] if isinstance(param, str) else np.stack(columns, axis=1)
    return SegmentFlow(end, sol.jacobian[:, :n], sensitivity, sol)


def cuts_at_switches(model: HybridModel) -> bool:
    """Are the segments of ``model``'s orbits cut at its switches: a model with modes whose transitions
    have no reset (else they are cut at the impacts, the transitions with one)?"""
    return model.has_modes and model.n_stops > 0 and not any(model.transition_resets)


@dataclass(frozen=True)
class SegmentLayout:
    """Where each unknown lies in ``u = (s_0, t_1, s_1, ..., t_k, s_k, p)``.

    Attributes
    ----------
    n_states
        States of the model (``N``).
    stops
        The stop of each impact, in order over one period from the section.
    mode
        A model with modes: the mode on the section, which the first segment starts in (each other
        starts in its impact's target mode, :meth:`start_mode`); None without modes.
    switches
        The segments end on switches (transitions without a reset, :func:`cuts_at_switches`), not
        on impacts: ``stops`` are those switches' transitions and ``s_i`` the state at switch ``i``.
    contact
        A switch layout: the index in ``stops`` of a cut that is a grazing contact with its
        transition's guard (tangent to it in the transition's source mode, no switch), where the
        equations gain the contact's condition ``L_f h = 0`` and the parameter is solved for
        (:mod:`grazing.orbits.segmented_grazing`); None: every cut is a switch.
    """

    n_states: int
    stops: tuple[int, ...]
    mode: str | None = None
    switches: bool = False
    contact: int | None = None

    def start_mode(self, model: HybridModel, i: int) -> str | None:
        """The mode segment ``i`` starts in: the section's (``i = 0``), else impact ``i``'s target mode
        (the mode before it, after a :attr:`contact`)."""
        if self.mode is None or i == 0:
            return self.mode
        if i - 1 == self.contact:
            return model.transition_source[self.stops[i - 1]]
        return model.transition_target[self.stops[i - 1]]

    def touching(self, i: int) -> int | None:
        """The transition whose guard segment ``i`` starts or ends on at the :attr:`contact` (None)."""
        if self.contact is None or i not in (self.contact, self.contact + 1):
            return None
        return self.stops[self.contact]

    @property
    def impacts(self) -> int:
        return len(self.stops)

    @property
    def size(self) -> int:
        """Unknowns besides the parameter: ``N + k (N + 1)``."""
        return self.n_states + self.impacts * (self.n_states + 1)

    def state(self, u: np.ndarray, i: int) -> np.ndarray:
        """``s_i``: the section state (``i = 0``) or the state just after impact ``i``."""
        n = self.n_states
        start = 0 if i == 0 else n + (i - 1) * (n + 1) + 1
        return u[start : start + n]

    def state_index(self, i: int) -> int:
        n = self.n_states
        return 0 if i == 0 else n + (i - 1) * (n + 1) + 1

    def time_index(self, i: int) -> int:
        """Index of ``t_i`` (``i >= 1``)."""
        return self.n_states + (i - 1) * (self.n_states + 1)

    def pack(self, orbit: PeriodicOrbit, param_value: float) -> np.ndarray:
        """``u`` of a periodic orbit found by single shooting (its impacts give the times and states)."""
        m = orbit.model
        parts = [orbit.state]
        if self.switches:  # (no reset: the state at each switch)
            assert orbit.switch_states is not None
            for t, y in zip(orbit.switch_times, orbit.switch_states):
                parts += [np.array([t]), np.asarray(y, dtype=float)]
            return np.concatenate([*parts, [param_value]])
        assert orbit.impact_states is not None
        for t, y, j in zip(orbit.impact_times, orbit.impact_states, orbit.impact_stops):
            parts += [np.array([t]), m.reset(y, t, int(j))]
        return np.concatenate([*parts, [param_value]])


def layout_of(orbit: PeriodicOrbit) -> SegmentLayout:
    """The segment layout of an orbit's impacts (of its switches, where :func:`cuts_at_switches`)."""
    m = orbit.model
    if cuts_at_switches(m) and _crossing_switches(m, orbit.switch_transitions):
        return SegmentLayout(m.n_states, tuple(int(j) for j in orbit.switch_transitions), orbit.mode, True)
    return SegmentLayout(m.n_states, tuple(int(j) for j in orbit.impact_stops), orbit.mode)


def _crossing_switches(model: HybridModel, transitions: np.ndarray) -> bool:
    """Are there switches, all of them crossings of a transition (none a sliding entry or exit)?"""
    return len(transitions) > 0 and bool(np.all(np.asarray(transitions) < model.n_stops))


def segmented_equations(
    model: HybridModel, param: str | tuple[str, ...] | None, period: int, t0: float, layout: SegmentLayout,
    stop: int = 0,
):  # fmt: skip
    """``u -> (F, DF, orbit)`` for the multiple-shooting equations of a period-``period`` orbit.

    ``u`` is laid out by ``layout`` (:class:`SegmentLayout`), the parameter ``param`` last;
    ``stop`` is the stop whose guard minimum the orbit reports.  ``F`` has as many rows as
    ``u`` has entries but one (``DF`` one column more), as :func:`branch_equations`'s.  With
    ``param`` None the parameters are fixed: the last entry of ``u`` is ignored and the last
    column of ``DF`` is zero (:func:`segmented_newton`).  With a tuple of parameters (a curve
    in two parameters, :mod:`grazing.orbits.segmented_curves`) they are the last entries of
    ``u``, in order, and ``DF`` has a column for each.  On a model with modes each segment
    starts in :meth:`SegmentLayout.start_mode` and follows the switches and sliding of the
    vector fields (:func:`segment_flow`); a segment that ends in another mode than its impact
    leaves (or the last in another than the section's) is a :class:`ConvergenceError`.

    Examples
    --------
    >>> import grazing
    >>> from grazing.orbits import find_orbit
    >>> m = grazing.models.impact_oscillator(omega=0.8)
    >>> o = find_orbit(m)  # (period 1, two impacts: three segments)
    >>> lay = layout_of(o)
    >>> F, DF, orbit = segmented_equations(m, "omega", 1, o.t0, lay)(lay.pack(o, 0.8))
    >>> bool(abs(F).max() < 1e-10), DF.shape, bool(np.allclose(orbit.multipliers, o.multipliers))
    (True, (8, 9), True)
    """
    n, k = layout.n_states, layout.impacts
    modes = model.has_modes
    names = () if param is None else (param,) if isinstance(param, str) else tuple(param)
    order = [p.name for p in model.parameters]
    pidx = [order.index(name) for name in names]
    size, extra = layout.size, max(1, len(names))
    pcols = slice(size, size + len(names))
    contact = layout.contact  # (a grazing contact: one more row, its rate; the payload a GrazingPoint)
    rows = size + (contact is not None)

    def evaluate(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, PeriodicOrbit]:
        values = u[size : size + len(names)]
        m = model.with_params(**{q: float(v) for q, v in zip(names, values)}) if names else model
        T = m.period
        t_end = t0 + period * T
        F = np.zeros(rows)
        DF = np.zeros((rows, size + extra))
        M = np.eye(n)
        factors: list[np.ndarray] = []  # (each segment's Jacobian and saltation, in order: a contact's)
        times = [t0] + [float(u[layout.time_index(i)]) for i in range(1, k + 1)] + [t_end]
        if np.any(np.diff(times) <= 0.0):
            raise ConvergenceError("the impacts of the orbit's segments are no longer in order")
        runs: list[Solution] = []
        pre: list[np.ndarray] = []
        speeds: list[float] = []
        row = 0
        cut_switches = layout.switches
        for i in range(k + 1):
            s_i = layout.state(u, i)
            ta, tb = times[i], times[i + 1]
            start_mode = layout.start_mode(m, i)
            behind = cut_switches and i > 0 and i - 1 != contact and not _in_mode(m, s_i, ta, start_mode)
            if behind:  # (a Newton iterate a hair behind the switch's surface: from the mode it leaves)
                start_mode = m.transition_source[layout.stops[i - 1]]
            seg = segment_flow(m, s_i, ta, tb, names, start_mode, layout.touching(i))
            runs.append(seg.solution)
            y = seg.end
            end_mode = seg.solution.mode_final
            crossed = False  # (a switch layout: the run crossed its end's switch just before tb)
            if cut_switches:
                crossed = _check_switch_segment(m, layout, i, seg.solution, behind)
            elif modes:
                _check_segment_modes(m, layout, i, end_mode)
            si, col_t_end = layout.state_index(i), (layout.time_index(i + 1) if i < k else None)
            # d y = Phi d s_i - Phi f(s_i, ta) d ta + f(y, tb) d tb + S d p (the fields of the modes the
            # segment starts and ends in: Phi carries any switch between them, a sliding entry at ta too)
            f_start = m.vector_field(s_i, ta, start_mode)
            f_end = m.vector_field(y, tb, end_mode)
            dy = np.zeros((n, size + extra))
            dy[:, si : si + n] = seg.jacobian
            if i > 0:
                dy[:, layout.time_index(i)] = -seg.jacobian @ f_start
            if col_t_end is not None:
                dy[:, col_t_end] = f_end
            for c, name in enumerate(names):
                tp = seg.solution.info["period_gradient"][name]  # dT/dp: the return time t0 + n T moves
                dy[:, size + c] = seg.sensitivity[:, c] + (f_end * period * tp if i == k else 0.0)
            M = seg.jacobian @ M
            factors.append(seg.jacobian)
            if i == k:  # the return to the section
                F[row : row + n] = y - layout.state(u, 0)
                DF[row : row + n] = dy
                DF[row : row + n, 0:n] -= np.eye(n)
                row += n
                continue
            j = layout.stops[i]
            cd = m.contact_derivatives(y, tb, j)
            F[row] = cd["h"]
            DF[row] = cd["h_x"] @ dy
            DF[row, col_t_end] += cd["h_t"]
            if names:
                DF[row, pcols] += np.asarray(cd["h_p"])[pidx]
            row += 1
            if cut_switches:  # (no reset: continuity, the state at the switch the next segment's start)
                nxt = layout.state_index(i + 1)
                F[row : row + n] = layout.state(u, i + 1) - y
                DF[row : row + n] = -dy
                DF[row : row + n, nxt : nxt + n] += np.eye(n)
                row += n
                pre.append(y)
                speeds.append(-cd["rate"])
                if i == contact:  # (tangent to the guard, no switch: the rate's row, last)
                    F[size] = cd["rate"]
                    DF[size] = cd["rate_x"] @ dy
                    DF[size, col_t_end] += cd["rate_t"]
                    if names:
                        DF[size, pcols] += np.asarray(cd["rate_p"])[pidx]
                    factors.append(np.eye(n))
                elif not crossed:
                    M = m.saltation(y, tb, j) @ M
                    factors.append(m.saltation(y, tb, j))
                else:
                    factors.append(np.eye(n))  # (the run's Jacobian carries the saltation)
                continue
            g = m.reset(y, tb, j)
            _, _, gx = m.jacobians(y, tb, j)
            gt = np.asarray(m.numeric("g_t", j)(list(y), tb, list(m.param_vector)), dtype=float).reshape(n)
            nxt = layout.state_index(i + 1)
            F[row : row + n] = layout.state(u, i + 1) - g
            DF[row : row + n] = -(gx @ dy)
            DF[row : row + n, col_t_end] -= gt
            if names:
                gp = np.asarray(m.numeric("g_p", j)(list(y), tb, list(m.param_vector)), dtype=float)
                DF[row : row + n, pcols] -= gp.reshape(n, -1)[:, pidx]
            DF[row : row + n, nxt : nxt + n] += np.eye(n)
            row += n
            pre.append(y)
            speeds.append(-cd["rate"])  # (positive: the guard decreases into the stop)
            M = m.saltation(y, tb, j) @ M
        if contact is not None:
            return F, DF, _contact_run(m, layout, u, times, factors)
        orbit = _segmented_orbit(m, layout, u, t0, period, times, pre, speeds, runs, M, F, stop)
        return F, DF, orbit

    return evaluate


@dataclass(frozen=True)
class ContactRun:
    """The payload of the segmented equations with a grazing :attr:`SegmentLayout.contact`.

    Attributes
    ----------
    model
        The model at the parameter values of ``u``.
    contact
        The state at the contact (on the guard of :attr:`transition`).
    t_contact
        Its time.
    transition
        The transition whose guard is touched.
    monodromy
        The Jacobian of the period map on the section through the contact (the product of the
        segments' Jacobians and the switches' saltation matrices from the contact round to it).
    accel
        ``L_f^2 h`` at the contact (positive: the orbit turns back from the guard).
    switches
        The orbit's switches of mode per period (the contact none).
    """

    model: HybridModel
    contact: np.ndarray
    t_contact: float
    transition: int
    monodromy: np.ndarray
    accel: float
    switches: int


def _contact_run(
    m: HybridModel, layout: SegmentLayout, u: np.ndarray, times: list[float], factors: list[np.ndarray]
) -> ContactRun:
    """:class:`ContactRun` of the segmented equations at ``u`` (``factors``: each segment's Jacobian and
    the saltation matrix at each cut, in order from the section)."""
    c = layout.contact
    assert c is not None
    j, y, t = layout.stops[c], np.array(layout.state(u, c + 1), dtype=float), times[c + 1]
    M = np.eye(layout.n_states)
    for f in [*factors[2 * c + 2 :], *factors[: 2 * c + 2]]:  # (from the contact round to it)
        M = f @ M
    accel = float(m.contact_derivatives(y, t, j)["accel"])
    return ContactRun(m, y, t, j, M, accel, layout.impacts - 1)


def _check_segment_modes(m: HybridModel, layout: SegmentLayout, i: int, end_mode: str | None) -> None:
    """Raise :class:`ConvergenceError` where segment ``i`` ends in another mode than its impact leaves
    (the last segment: than the section's mode)."""
    k = layout.impacts
    want = layout.mode if i == k else m.transition_source[layout.stops[i]]
    if end_mode != want:
        what = (
            "returns to the section"
            if i == k
            else f"reaches impact {i + 1} ({m.stop_names[layout.stops[i]]!r})"
        )
        raise ConvergenceError(
            f"segment {i} of the orbit {what} in mode {end_mode!r}, not in {want!r}: its switches of mode "
            "have changed"
        )


def _in_mode(m: HybridModel, x: np.ndarray, t: float, mode: str | None) -> bool:
    """Does ``x`` satisfy the guards of ``mode``'s transitions (to the engine's tolerance)?"""
    try:
        m.check_state(x, t, mode=mode)
    except InvalidStateError:
        return False
    return True


def _check_switch_segment(m: HybridModel, layout: SegmentLayout, i: int, run: Solution, behind: bool) -> bool:
    """Check segment ``i`` of a switch layout: it stays in its mode, or crosses only its end's switch
    (rounding puts the crossing a hair before the end); True where it crossed it.  ``behind``: the run
    started behind its start's surface, in the mode before, and first crosses that switch again.  The
    last segment returns in the section's mode.  Raise :class:`ConvergenceError` otherwise."""
    sw = run.switches
    passed = [] if sw is None else [int(j) for j in sw.transition]
    if behind:
        if not passed or passed[0] != layout.stops[i - 1]:
            raise ConvergenceError(
                f"segment {i} of the orbit starts behind switch {m.stop_names[layout.stops[i - 1]]!r} and "
                "does not cross it: its switches have changed"
            )
        passed = passed[1:]
    start = layout.start_mode(m, i)
    if i == layout.contact:  # (to a grazing contact: no switch on the way, nor at its end)
        if passed or run.mode_final != start:
            raise ConvergenceError(
                f"segment {i} of the grazing orbit switches mode ({len(passed)} switches) before its contact "
                f"with {m.stop_names[layout.stops[i]]!r}: it crosses the surface"
            )
        return False
    if i == layout.impacts:
        if passed or run.mode_final != layout.mode:
            raise ConvergenceError(
                f"the last segment of the orbit switches mode ({len(passed)} switches) before it returns to "
                f"the section in mode {layout.mode!r}: its switches have changed"
            )
        return False
    j = layout.stops[i]
    if not passed and run.mode_final == start:
        return False
    if passed == [j] and run.mode_final == m.transition_target[j]:
        return True
    raise ConvergenceError(
        f"segment {i} of the orbit does not run in mode {start!r} to switch {m.stop_names[j]!r} (it switches "
        f"{len(passed)} times, ends in {run.mode_final!r}): its switches have changed"
    )


def _least(rows) -> tuple[float, float, np.ndarray] | None:
    rows = [r for r in rows if r is not None]
    return min(rows, key=lambda r: r[0]) if rows else None


def _segmented_orbit(
    m: HybridModel, layout: SegmentLayout, u, t0, period, times, pre, speeds, runs, M, F, stop
) -> PeriodicOrbit:
    """The payload: the orbit's section state, monodromy, impacts and guard minima over the segments."""
    if m.has_modes:
        return _segmented_orbit_modes(m, layout, u, t0, period, times, pre, speeds, runs, M, F, stop)
    n_stops = m.n_stops
    by_stop = []
    approach = []
    edge = 1e-9 * m.period  # (a segment's ends are the impacts, not closest approaches in free flight)
    for j in range(n_stops):
        by_stop.append(_least(r.guard_min_by_stop[j] for r in runs if r.guard_min_by_stop))
        inner = []
        for i, r in enumerate(runs):
            a = r.approach_by_stop[j] if r.approach_by_stop else None
            if a is not None and times[i] + edge < a[1] < times[i + 1] - edge:
                inner.append(a)
        approach.append(_least(inner))
    gmin = by_stop[stop]
    assert gmin is not None
    v = np.array(speeds)
    return PeriodicOrbit(
        model=m,
        state=np.array(layout.state(u, 0), dtype=float),
        t0=float(t0),
        period=period,
        impacts=layout.impacts,
        monodromy=M,
        multipliers=sorted_multipliers(M),
        guard_min=gmin[0],
        t_guard_min=gmin[1],
        min_impact_speed=float(v.min()) if v.size else math.nan,
        virtual=False,
        residuals=(float(np.max(np.abs(F))),),
        x_guard_min=gmin[2],
        impact_times=np.array(times[1:-1]),
        impact_speeds=v,
        impact_states=np.array(pre).reshape(-1, layout.n_states),
        approach=approach[stop],
        stop=stop,
        impact_stops=np.array(layout.stops, dtype=int),
        guard_min_by_stop=tuple(by_stop),  # type: ignore[arg-type]
        approach_by_stop=tuple(approach),
    )


def _segmented_orbit_modes(
    m: HybridModel, layout: SegmentLayout, u, t0, period, times, pre, speeds, runs, M, F, stop
) -> PeriodicOrbit:
    """:func:`_segmented_orbit` on a model with modes: no guard minima (the engine keeps none through
    modes), the switches of the segments and of the impacts that change the mode, and the transitions
    with a reset that the segments pass through (:func:`_passed_stops`).  A switch layout: no impacts,
    its switches the segments' ends (no run switches elsewhere)."""
    if layout.switches:
        return PeriodicOrbit(
            model=m, state=np.array(layout.state(u, 0), dtype=float), t0=float(t0), period=period,
            impacts=0, monodromy=M, multipliers=sorted_multipliers(M), guard_min=math.nan,
            t_guard_min=math.nan, min_impact_speed=math.nan, virtual=False,
            residuals=(float(np.max(np.abs(F))),), impact_states=np.zeros((0, layout.n_states)), stop=stop,
            mode=layout.mode, switch_times=np.array(times[1:-1], dtype=float),
            switch_transitions=np.array(layout.stops, dtype=int),
            switch_states=np.array([layout.state(u, i) for i in range(1, layout.impacts + 1)]),
        )  # fmt: skip
    sw_t: list[float] = []
    sw_j: list[int] = []
    for i, r in enumerate(runs):
        if r.switches is not None and len(r.switches):
            keep = r.switches.t < times[i + 1]
            sw_t += r.switches.t[keep].tolist()
            sw_j += r.switches.transition[keep].tolist()
        if i < layout.impacts:
            j = layout.stops[i]
            if m.transition_source[j] != m.transition_target[j]:  # (an impact that changes the mode)
                sw_t.append(times[i + 1])
                sw_j.append(j)
    order = np.argsort(sw_t, kind="stable")
    v = np.array(speeds)
    return PeriodicOrbit(
        model=m, state=np.array(layout.state(u, 0), dtype=float), t0=float(t0), period=period,
        impacts=layout.impacts, monodromy=M, multipliers=sorted_multipliers(M), guard_min=math.nan,
        t_guard_min=math.nan, min_impact_speed=float(v.min()) if v.size else math.nan, virtual=False,
        residuals=(float(np.max(np.abs(F))),), impact_times=np.array(times[1:-1]), impact_speeds=v,
        impact_states=np.array(pre).reshape(-1, layout.n_states), stop=stop,
        impact_stops=np.array(layout.stops, dtype=int), mode=layout.mode,
        switch_times=np.array(sw_t, dtype=float)[order], switch_transitions=np.array(sw_j, dtype=int)[order],
        passed_stops=_passed_stops(m, layout, u, times),
    )  # fmt: skip


def _passed_stops(
    m: HybridModel, layout: SegmentLayout, u: np.ndarray, times: list[float]
) -> tuple[str, ...]:
    """The transitions with a reset that the segments of ``u`` pass through before their ends: each
    segment run again with the resets watched, to just short of its end (an impact there is one the
    orbit does not have)."""
    passed: list[str] = []
    edge = 1e-9 * m.period
    for i in range(layout.impacts + 1):
        s_i, mode = layout.state(u, i), layout.start_mode(m, i)
        ta, tb = times[i], times[i + 1] - edge
        try:
            periods, phase = _segment_span(m, ta, tb)
            sol = simulate(m, s_i, t0=ta, periods=periods, phase=phase, impacts="all", mode=mode)
        except InvalidStateError:  # (it starts beyond a reset's guard of its mode)
            passed += [
                name for j, name in enumerate(m.stop_names)
                if m.transition_source[j] == mode and m.transition_resets[j] and m.guard(s_i, ta, j) < 0.0
            ]  # fmt: skip
            continue
        except (ConvergenceError, SimulationError):
            continue
        passed += [m.stop_names[int(j)] for j in sol.impacts.stop]
    return tuple(dict.fromkeys(passed))


def run_layout(
    model: HybridModel, x: np.ndarray, t0: float, period: int, stop: int = 0, mode: str | None = None
):  # fmt: skip
    """The segments of the run of ``period`` forcing periods from ``x`` at ``t0`` (its impacts) and its ``u``.

    ``mode``: a model with modes, the mode of ``x`` (its initial mode by default).  Returns
    ``(layout, u)`` (``u`` with a trailing 0 for the parameter), or None where the run has no
    impact, sticks or returns in another mode.
    """
    if model.has_modes:
        mode = model.mode_names[model.mode_index(mode)]
    sol = simulate(
        model, x, t0=t0, periods=period, phase=2 * math.pi * (t0 / model.period % 1.0), impacts="all",
        stop_name=stop, mode=mode,
    )  # fmt: skip
    imp = sol.impacts
    if len(sol.sticking) or sol.mode_final != (mode if model.has_modes else None):
        return None
    if cuts_at_switches(model):
        sw = sol.switches
        if sw is None or not _crossing_switches(model, sw.transition):
            return None
        layout = SegmentLayout(model.n_states, tuple(int(j) for j in sw.transition), mode, True)
        parts = [np.asarray(x, dtype=float)]
        for t, y in zip(sw.t, sw.state):
            parts += [np.array([t]), np.asarray(y, dtype=float)]
        return layout, np.concatenate([*parts, [0.0]])
    if not len(imp):
        return None
    layout = SegmentLayout(model.n_states, tuple(int(j) for j in imp.stop), mode)
    parts = [np.asarray(x, dtype=float)]
    for t, y, j in zip(imp.t, imp.state, imp.stop):
        parts += [np.array([t]), model.reset(y, t, int(j))]
    return layout, np.concatenate([*parts, [0.0]])


def segmented_newton(
    model: HybridModel, x: np.ndarray, t0: float, period: int, *, tol: float, max_iter: int, stop: int = 0,
    mode: str | None = None,
) -> PeriodicOrbit:  # fmt: skip
    """The period-``period`` orbit near the run from ``x`` at ``t0``, by Newton's method on the segmented
    equations (the run's impacts give the segments; on a model with modes, from ``x`` in ``mode``, its
    impacts those of its transitions with a reset; on one without resets its switches,
    :func:`cuts_at_switches`).

    Raises
    ------
    ConvergenceError
        Where the run has no impact (no switch, or one that slides, where cut at switches), Newton's
        method does not reach ``tol``, or the orbit it finds is not a motion of the system (an impact
        speed or a switch's crossing rate not positive, a segment through a stop).
    """
    start = run_layout(model, x, t0, period, stop, mode)
    if start is None:
        raise ConvergenceError("the run from the guess has no impact (or switch) to make segments of")
    layout, u = start
    return solve_segments(model, layout, u, t0, period, tol=tol, max_iter=max_iter, stop=stop)


def solve_segments(
    model: HybridModel, layout: SegmentLayout, u: np.ndarray, t0: float, period: int, *, tol: float,
    max_iter: int, stop: int = 0,
) -> PeriodicOrbit:  # fmt: skip
    """The period-``period`` orbit on the section ``t0`` by Newton's method on the segmented equations of
    ``layout`` from the unknowns ``u`` (the parameters fixed), as :func:`segmented_newton` (its errors)."""
    u = np.array(u, dtype=float)
    evaluate = segmented_equations(model, None, period, t0, layout, stop)
    residuals: list[float] = []
    for _ in range(max_iter + 1):
        F, DF, orbit = evaluate(u)
        residuals.append(float(np.max(np.abs(F))))
        if not np.isfinite(residuals[-1]):
            break
        if residuals[-1] <= tol:
            speeds = orbit.impact_speeds
            if layout.switches:  # (a switch crossed at zero rate or backwards is no crossing)
                speeds = switch_rates(orbit.model, orbit.switch_times, orbit.switch_states, layout.stops)
            if orbit.crossed_stops or float(np.min(speeds)) <= 0.0:
                raise ConvergenceError(
                    "the segmented orbit is not a motion of the system (it passes through a stop, or an "
                    "impact has no speed)"
                )
            return dataclasses.replace(orbit, residuals=tuple(residuals))
        try:
            u[:-1] = u[:-1] - np.linalg.solve(DF[:, :-1], F)
        except np.linalg.LinAlgError:
            break
    raise ConvergenceError(
        f"Newton's method on the segmented equations did not converge: residual {residuals[-1]:.3g} after "
        f"{len(residuals) - 1} iterations"
    )


def resectioned(orbit: PeriodicOrbit, t_new: float) -> tuple[SegmentLayout, np.ndarray, float] | None:
    """``(layout, u, t0)``: the segments of ``orbit`` on the section through the next time ``t_new (mod T)``
    after its own, from its own cuts: the state there is one segment's flow from the cut before it
    (never a run over a whole period, which a strongly unstable orbit's rounding would leave), its mode
    that segment's, and the cuts after it come first (the others a period later).  ``t0`` lies in
    ``[0, T)``.  None where the orbit has no cut, or the flow leaves that segment's mode."""
    m = orbit.model
    layout = layout_of(orbit)
    if not layout.impacts or (layout.switches and orbit.switch_states is None):
        return None
    T, span = m.period, orbit.period * m.period
    u = layout.pack(orbit, 0.0)
    t_abs = orbit.t0 + (t_new - orbit.t0) % T
    times = np.array([u[layout.time_index(i)] for i in range(1, layout.impacts + 1)])
    i = int(np.count_nonzero(times <= t_abs))  # (the segment t_abs lies on)
    ta = orbit.t0 if i == 0 else float(times[i - 1])
    x, mode = np.array(layout.state(u, i), dtype=float), layout.start_mode(m, i)
    if t_abs > ta:
        try:
            run = segment_flow(m, x, ta, t_abs, None, mode=mode).solution
        except (ConvergenceError, SimulationError, InvalidStateError):
            return None
        if run.mode_final != mode or (run.switches is not None and len(run.switches.t)):
            return None
        x = run.x_final
    shift = round((t_abs - t_new) / T) * T
    order = [*range(i + 1, layout.impacts + 1), *range(1, i + 1)]
    parts = [x]
    for j in order:
        t = float(times[j - 1]) + (span if j <= i else 0.0) - shift
        parts += [np.array([t]), np.array(layout.state(u, j), dtype=float)]
    moved = dataclasses.replace(layout, stops=tuple(layout.stops[j - 1] for j in order), mode=mode)
    return moved, np.concatenate([*parts, [0.0]]), t_abs - shift


def switch_rates(model: HybridModel, times, states, transitions) -> list[float]:
    """The rate at which each switch's guard falls where it is crossed (positive: a crossing), as an
    impact's speed (transitions without a reset: the state is the same either side)."""
    return [
        -float(model.contact_derivatives(y, t, int(j))["rate"]) for t, y, j in zip(times, states, transitions)
    ]


def cut_speeds(model: HybridModel, run: Solution) -> np.ndarray | None:
    """The speeds (absolute) at the ends of the segments of ``run``: its impacts', or its switches'
    crossing rates where :func:`cuts_at_switches`; None where it has nothing to cut at (no impact; no
    switch, or a sliding one)."""
    if cuts_at_switches(model):
        sw = run.switches
        if sw is None or not _crossing_switches(model, sw.transition):
            return None
        return np.abs(switch_rates(model, sw.t, sw.state, sw.transition))
    return np.abs(run.impacts.speed) if run.n_impacts else None


REORDER_REACH = 4.0
""":func:`reordered` looks for two impacts changing order within this many of the continuation's
largest steps ahead of the last point (where it stalled, the order changes just ahead)."""


@dataclass(frozen=True)
class Reordering:
    """Two consecutive impacts on different stops that change order just ahead of a point.

    Attributes
    ----------
    first
        The index (from 0, in the order of the point's layout) of the earlier of the two.
    layout
        The layout with the two swapped.
    u
        The unknowns in ``layout``, past the change: the point's, moved along its tangent to twice the
        distance at which the two impact times meet, with the two impacts' states made consistent
        (one segment's flow and reset each).
    """

    first: int
    layout: SegmentLayout
    u: np.ndarray


def reordered(
    model: HybridModel, layout: SegmentLayout, t0: float, u: np.ndarray, tangent: np.ndarray,
    params: tuple[str, ...], reach: float,
) -> Reordering | None:  # fmt: skip
    """Where two consecutive impacts on different stops are about to change order along ``tangent``.

    The segments' order is fixed: where an impact on one stop comes to pass an impact on another (two
    bodies, or two stops of one), the segmented equations break down (their times would have to
    cross) and the continuation stalls short of it, while the orbit itself goes on, its impacts in the
    other order.  ``t0`` is the section's time, ``u`` the last point (``params`` its last entries,
    after ``layout.size``), ``tangent`` its unit tangent, ``reach`` how far ahead along it to look.
    Returns the swapped layout and the point past the change in it (:class:`Reordering`), for
    Newton's method to correct; None where no two impact times meet within ``reach``.

    Examples
    --------
    Two impacts at ``t = 1`` and ``1.1`` whose times move apart along the tangent do not change order:

    >>> import grazing
    >>> lay = SegmentLayout(1, (0, 1))  # u = (s0, t1, s1, t2, s2, p)
    >>> u, tangent = np.array([0.0, 1.0, 0.0, 1.1, 0.0, 0.0]), np.array([0.0, -1.0, 0.0, 1.0, 0.0, 0.0])
    >>> reordered(grazing.models.impact_oscillator(), lay, 0.0, u, tangent, (), 1.0) is None
    True
    """
    k = layout.impacts
    if k < 2:
        return None
    times = np.array([u[layout.time_index(i)] for i in range(1, k + 1)])
    rates = np.array([tangent[layout.time_index(i)] for i in range(1, k + 1)])
    best: tuple[float, int] | None = None
    for i in range(k - 1):
        closing = rates[i] - rates[i + 1]
        gap = times[i + 1] - times[i]
        if layout.stops[i] == layout.stops[i + 1] or closing <= 0.0 or gap <= 0.0:
            continue
        s = gap / closing
        if s <= reach and (best is None or s < best[0]):
            best = (s, i)
    if best is None:
        return None
    s, i = best
    ahead = u + 2.0 * s * tangent
    stops = list(layout.stops)
    stops[i], stops[i + 1] = stops[i + 1], stops[i]
    swapped = SegmentLayout(layout.n_states, tuple(stops), layout.mode)
    n = layout.n_states
    m = model.with_params(**{q: float(v) for q, v in zip(params, ahead[layout.size :])}) if params else model
    new = ahead.copy()
    t_a, t_b = float(ahead[layout.time_index(i + 1)]), float(ahead[layout.time_index(i + 2)])
    if not t_b < t_a:
        return None
    # The pair, now in the other order: the second's time first; each state one flow and one reset on.
    start = float(ahead[layout.time_index(i)]) if i > 0 else float(t0)
    state = layout.state(ahead, i).copy()
    for j, t in ((i, t_b), (i + 1, t_a)):
        flow = segment_flow(m, state, start, t, None, swapped.start_mode(m, j))
        state = m.reset(flow.end, t, swapped.stops[j])
        new[swapped.time_index(j + 1)] = t
        new[swapped.state_index(j + 1) : swapped.state_index(j + 1) + n] = state
        start = t
    return Reordering(i, swapped, new)
