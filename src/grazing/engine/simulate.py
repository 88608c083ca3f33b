"""``simulate``: event-driven simulation of a hybrid model."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from grazing.core.model import HybridModel
from grazing.core.options import (
    SaveAt,
    Solver,
    Tangent,
    refuse_unknown,
    step_limit,
    with_shorthands,
)
from grazing.core.solution import Impacts, Solution, Switches
from grazing.engine.runner import DiscontinuityMap, Runner, check_map_stop
from grazing.errors import InvalidParameterError

CHUNK_PERIODS = 4096
"""Runs are integrated in chunks of this many forcing periods."""


def simulate(
    model: HybridModel,
    x0: Sequence[float] | np.ndarray | None = None,
    *,
    t0: float = 0.0,
    save: SaveAt | None = None,
    tangent: Tangent | None = None,
    solver: Solver | None = None,
    events: bool = True,
    zdm: DiscontinuityMap | None = None,
    touching: bool = False,
    stop_name: int | str | None = None,
    progress: Callable[[int, int], None] | None = None,
    mode: str | None = None,
    **shorthands: Any,
) -> Solution:
    """Simulate a hybrid model, never missing an impact.

    The flow is integrated by a Taylor method of order ~20 with the guard
    expanded alongside the state; every step's guard polynomial is searched
    for roots by Bernstein subdivision, so impacts of any depth inside a step
    are found.  Complete chattering is summed and continued as sticking.

    Parameters
    ----------
    model
        The model with its parameter values.
    x0
        Initial state at time ``t0`` (default: zeros). Must satisfy the guard.
    t0
        Initial time (for forced models, this sets the forcing phase).
    save
        What to record (:class:`~grazing.core.options.SaveAt`): ``periods``
        sampled (default 100), ``transient`` periods run first and discarded,
        the stroboscopic ``phase`` (samples at ``t = (phase/2pi + k) T``),
        ``trajectory`` points per period over the sampled span (plus both
        states at each impact), which ``impacts`` to record (``"sampled"``
        span, ``"all"``, ``"none"``), ``guard_min`` (the smallest guard value
        and the closest approach to the stop, :attr:`Solution.approach_min`;
        on a model with modes, of the transitions with a reset, each over the
        time the run spends in its source mode: elsewhere it is no stop of the
        motion; a transition without a reset reports ``inf``).
    tangent
        Tangent dynamics (:class:`~grazing.core.options.Tangent`):
        ``jacobian`` (``d x_final / d x0``, saltation matrices at impacts),
        ``sensitivities`` (parameter names whose derivatives are appended as
        columns: the final sample at the same forcing phase after the same
        number of periods, ``t0`` fixed, so a parameter that sets the period
        moves the sample time), ``lyapunov`` (exponents over the sampled span).
    solver
        Integrator settings (:class:`~grazing.core.options.Solver`): ``tol``
        (local error tolerance, sets the Taylor order), ``max_steps``
        (default :func:`~grazing.core.options.step_limit` of ``transient + periods``), ``chatter_tol``
        (chattering shorter than this fraction of a period is summed to its
        accumulation point and continued as sticking).
    **shorthands
        Any field of the three option objects by name, as a keyword
        (``periods=20``, ``jacobian=True``, ``tol=1e-10`` ...): it replaces
        that field of the object given (or of the defaults).
    events
        If False, the guard is ignored: the flow passes through the stop (no
        impacts).  ``guard_min`` then tells how far past the stop it reaches.
        On a model with modes only the transitions with a reset are ignored:
        the run still switches its vector field and slides.
    zdm
        A :class:`~grazing.engine.runner.DiscontinuityMap`: ignore the stop and
        apply Nordmark's discontinuity map once per period at the grazing
        phase instead (the map Pi of the paper's eq. 20, with the nonlinear flow).
        On a model with modes it stands for a stop of one mode (a reset back
        into it) and is applied only while the run is in that mode.
    touching
        The run starts and ends in tangential contact with the stop (``h = 0``
        and ``L_f h = 0``: a grazing orbit followed from its contact point);
        these two contacts are not impacts, every other one is.
    stop_name
        The stop (name or index; the first by default) that ``guard_min``,
        ``touching`` and ``zdm`` refer to, for models with several stops.
        Impacts on every stop are always found and recorded
        (:attr:`Impacts.stop`).
    progress
        Called as ``progress(periods_done, periods_total)`` after every chunk
        of :data:`CHUNK_PERIODS` periods (the run is always chunked the same
        way, so results do not depend on whether progress is shown).
    mode
        The mode a model with modes starts in; ``x0`` must lie in it.  By
        default the one ``x0`` lies in (:meth:`~grazing.HybridModel.start_mode`):
        the initial mode where ``x0`` is in its region (on its edge too), else
        the one other mode whose region it is in; a one-line error where that
        is ambiguous (outside the initial mode, on a surface between two
        others) or where it is in none.  Switches between modes are located as impacts
        are, and the Jacobian is carried across them by their saltation
        matrices (:attr:`Solution.switches`).

    Returns
    -------
    Solution

    Examples
    --------
    >>> import math, grazing
    >>> model = grazing.models.pendulum("B", eta=0.446, theta_hat=math.radians(40))
    >>> sol = grazing.simulate(model, [0.0, 0.0], transient=400, periods=20)
    >>> sol.period()
    5
    >>> save, tangent = grazing.SaveAt(periods=5), grazing.Tangent(sensitivities=("eta",))
    >>> grazing.simulate(model, sol.x_final, save=save, tangent=tangent).jacobian.shape
    (2, 3)
    """
    used: set[str] = set()
    save = with_shorthands(save, SaveAt, shorthands, used)
    tangent = with_shorthands(tangent, Tangent, shorthands, used)
    solver = with_shorthands(solver, Solver, shorthands, used)
    refuse_unknown("simulate", shorthands, used)
    if not isinstance(t0, (int, float, np.floating, np.integer)) or not math.isfinite(t0):
        raise InvalidParameterError(f"t0 must be a finite number, got {t0!r}")
    periods, transient, phase, trajectory = save.periods, save.transient, save.phase, save.trajectory
    impacts, guard_min = save.impacts, save.guard_min
    sens, lyapunov = tangent.sensitivities, tangent.lyapunov
    tol, max_steps, chatter_tol = solver.tol, solver.max_steps, solver.chatter_tol
    if zdm is not None and not model.periodic:
        raise InvalidParameterError("the discontinuity map needs a periodically forced model")
    if zdm is not None:
        check_map_stop(model, int(zdm.stop))
    allowed = (events or model.has_modes) and zdm is None  # (with the map, it may be past the grazing stop)
    x0 = np.zeros(model.n_states) if x0 is None else x0
    if model.has_modes:
        if mode is None and allowed:  # (the mode x0 lies in: the initial one where it lies in its region)
            mode = model.start_mode(x0, t0, resets=events)
        _refuse_on_modes(
            model,
            touching=touching,
            stop_name=stop_name,
            mode=mode,
        )
    elif mode is not None:
        model.mode_index(mode)  # (only the one mode's name)
    x = model.check_state(x0, t0, allowed=allowed, mode=mode, resets=events)
    start_mode = model.mode_index(mode)
    stop_index = model.stop_index(stop_name)
    use_var = tangent.variational
    n = model.n_states
    T = model.period
    run = Runner(
        model, x, t0=float(t0), phase=float(phase), tol=tol, variational=use_var, sensitivities=sens,
        events=events, chatter_tol=chatter_tol, zdm=zdm, touching=touching, stop=stop_index,
        mode=start_mode,
    )  # fmt: skip
    first_sample = run.next_sample_time
    ks_start = run.ks
    total = transient + periods
    if max_steps is None:
        max_steps = step_limit(total)
    done = 0
    steps = 0
    n_imp = 0
    parts: dict[str, list[np.ndarray]] = {
        k: [] for k in ("samples", "imp", "sticks", "traj", "switch", "modes")
    }
    slides: list[np.ndarray] = []
    log_sum = np.zeros(n)
    lyap_span = 0.0
    gmin: np.ndarray | None = None
    amin: np.ndarray | None = None
    jac_ok = True
    while done < total:
        chunk = min(CHUNK_PERIODS, total - done)
        keep = max(0, done + chunk - transient) - max(0, done - transient)
        t_chunk = run.t
        run.touch_end = touching and done + chunk == total
        seg = run.advance(
            chunk, keep, lyapunov=lyapunov, guard_min=guard_min, impacts=impacts,
            trajectory=trajectory, max_steps=max_steps - steps,
        )  # fmt: skip
        steps += seg.steps
        n_imp += seg.n_impacts
        jac_ok = jac_ok and seg.jacobian_valid
        traj = seg.trajectory
        if traj.shape[0] and done > transient and parts["traj"]:
            traj = traj[1:]  # the chunk's first point repeats the previous chunk's last
        for key, arr in (
            ("samples", seg.samples),
            ("imp", seg.impacts),
            ("sticks", seg.sticking),
            ("traj", traj),
            ("switch", seg.switches),
            ("modes", seg.sample_modes),
        ):
            parts[key].append(arr)
        if keep and model.sliding_modes:  # the recorded span's sliding intervals in this chunk
            t_span = t_chunk if done >= transient else first_sample + (transient - 1) * T
            slides.append(_sliding_intervals(model, seg.switches, t_span, run.vf, run.t))
        log_sum += seg.log_sums
        lyap_span += seg.lyap_span
        if guard_min and keep:  # the smallest over the chunks, for each stop
            gmin = _smaller_rows(gmin, seg.guard_min)
            amin = _smaller_rows(amin, seg.approach_min)
        done += chunk
        if progress is not None:
            progress(done, total)
    t_samples = first_sample + (transient + np.arange(periods)) * T
    jac = run.V if (use_var and not lyapunov) else None
    if jac is not None and sens and np.any(run.Tp):
        jac = _sample_time_terms(
            run, x, float(t0), ks_start + total - 1, float(t_samples[-1]), jac, start_mode
        )
    if jac is not None:
        jac = jac[:, : n + len(sens)].copy()  # the module may have more direction columns than asked
    imp = _concat(parts["imp"], 3 + n)
    traj = _concat(parts["traj"], 1 + n)
    imp_t = imp[:, 0]
    switches = None
    if model.has_modes:
        sw = _concat(parts["switch"], 2 + n)
        switches = Switches(
            t=sw[:, 0], transition=sw[:, 1].astype(int), state=sw[:, 2:], transition_names=model.switch_names,
            sources=model.switch_sources, targets=model.switch_targets,
        )  # fmt: skip
    return Solution(
        model=model,
        t=t_samples,
        samples=_concat(parts["samples"], n),
        impacts=Impacts(
            t=imp_t,
            phase=np.mod(imp_t, T) / T * 2 * math.pi,
            speed=imp[:, 1],
            state=imp[:, 2 : 2 + n],
            stop=imp[:, 2 + n].astype(int),
            stop_names=model.stop_names,
        ),
        n_impacts=int(n_imp),
        sticking=_merge_intervals(_concat(parts["sticks"], 2)),
        t_final=run.t,
        x_final=run.x,
        n_steps=int(steps),
        trajectory_t=traj[:, 0] if trajectory else None,
        trajectory=traj[:, 1:] if trajectory else None,
        jacobian=jac,
        jacobian_valid=jac_ok,
        lyapunov=log_sum / lyap_span if lyapunov else None,
        guard_min=_min_tuple(gmin[stop_index]) if gmin is not None else None,
        approach_min=_min_tuple(amin[stop_index]) if amin is not None and _found(amin[stop_index]) else None,
        guard_min_by_stop=tuple(_min_tuple(r) for r in gmin) if gmin is not None else None,
        approach_by_stop=(
            tuple(_min_tuple(r) if _found(r) else None for r in amin) if amin is not None else None
        ),
        info={
            "order": run.order,
            "tol": tol,
            "transient": transient,
            "phase": phase,
            "period_gradient": dict(zip(sens, run.Tp.tolist())),
        },
        switches=switches,
        mode_final=model.mode_names[run.vf] if model.has_modes else None,
        modes=np.concatenate([np.empty(0, np.int64), *parts["modes"]]) if model.has_modes else None,
        sliding=_merge_intervals(_concat(slides, 3)) if model.has_modes and impacts != "none" else None,
    )


def _refuse_on_modes(
    model: HybridModel,
    *,
    touching: bool,
    stop_name: int | str | None,
    mode: str | None,
) -> None:
    """One line for what ``simulate`` cannot do yet on a model with modes (``model.has_modes``) (the
    discontinuity map's stop is :func:`~grazing.engine.runner.check_map_stop`'s)."""
    if touching:  # (a contact with a transition's guard, in the transition's source mode)
        j, start = model.stop_index(stop_name), model.mode_names[model.mode_index(mode)]
        if model.transition_source[j] != start:
            raise InvalidParameterError(
                f"a run from a grazing contact with transition {model.stop_names[j]!r} starts in its source "
                f"mode {model.transition_source[j]!r}, not in {start!r}"
            )


def _sample_time_terms(
    run: Runner, x0: np.ndarray, t0: float, k_final: int, t_final: float, V: np.ndarray, start_mode: int = 0
) -> np.ndarray:
    """Parameter columns of ``V`` for samples whose time moves with a period-setting parameter.

    The engine's columns are derivatives at fixed ``(k, s)``: the run from the
    instant ``k0 T(p) + s0`` to ``k T(p) + s`` (:func:`~grazing.engine.runner`).
    ``simulate`` promises the derivative of the final sample with ``t0`` fixed
    and the sample at the same forcing phase after the same number of periods,
    ``t_final(p) = (k_final + s_phase/T) T(p)``.  The start then does not move
    (``+ Psi_x f(x0, t0) k0 dT/dp``) and the end moves by
    ``f(x_final) (t_final/T - k) dT/dp`` beyond the engine's end.  Without
    wrapping (``periodic=False``) the engine's derivatives are at fixed times
    and the samples are ``t0 + j T``.
    """
    n = run.model.n_states
    T = run.T
    V = V.copy()
    f_end = run.vector_field(run.x, run.s)
    if run.model.periodic:
        end = (k_final - run.k) + run.ss / T
        start = V[:, :n] @ run.vector_field(x0, t0, start_mode) * run.k_start
    else:
        end = (t_final - t0) / T
        start = np.zeros(n)
    V[:, n:] += np.outer(f_end * end + start, run.Tp)
    return V


def _found(info: np.ndarray | None) -> bool:
    return info is not None and bool(np.isfinite(info[0]))


def _smaller_rows(best: np.ndarray | None, new: np.ndarray) -> np.ndarray:
    """Row by row (one row per stop), the row with the smaller first entry."""
    if best is None:
        return new.copy()
    out = best.copy()
    better = new[:, 0] < best[:, 0]
    out[better] = new[better]
    return out


def _min_tuple(row: np.ndarray) -> tuple[float, float, np.ndarray]:
    return float(row[0]), float(row[1]), row[2:].copy()


def _concat(arrays: list[np.ndarray], width: int) -> np.ndarray:
    arrays = [a for a in arrays if a.shape[0]]
    return np.concatenate(arrays) if arrays else np.empty((0, width))


def _merge_intervals(iv: np.ndarray) -> np.ndarray:
    """Join sticking (or sliding) intervals that a chunk boundary split in two.

    Rows ``[start, end]``, or ``[start, end, surface]``: then only intervals
    on the same surface are joined.
    """
    if iv.shape[0] < 2:
        return iv
    out = [iv[0].copy()]
    for row in iv[1:]:
        same = row.shape[0] < 3 or row[2] == out[-1][2]
        if same and row[0] <= out[-1][1]:
            out[-1][1] = max(out[-1][1], row[1])
        else:
            out.append(row.copy())
    return np.array(out)


def _sliding_intervals(
    model: HybridModel, switches: np.ndarray, t_start: float, vf_end: int, t_end: float
) -> np.ndarray:
    """Rows ``[start, end, surface]`` of the sliding of a recorded span from ``t_start`` to ``t_end``.

    The span ends in mode ``vf_end``; ``switches`` are its rows ``[t, transition, state...]``
    (:attr:`HybridModel.switch_names`).  Sliding is the time spent in a sliding pseudo-mode
    (:attr:`HybridModel.sliding_modes`).  The mode after ``t_start`` is the source of the first switch
    after it (as :meth:`~grazing.core.solution.Solution.mode_spans` reads it), not the mode the run was
    in when the span began: a run starting on a sliding surface switches into sliding at ``t_start``
    itself, after that.
    """
    sliding = model.sliding_modes
    modes = model.mode_names
    source = [modes.index(name) for name in model.switch_sources]
    target = [modes.index(name) for name in model.switch_targets]
    later = [(t, int(j)) for t, j in switches[:, :2] if t > t_start]  # (impacts="all": earlier ones too)
    rows = []
    mode, since = (source[later[0][1]] if later else vf_end), t_start
    for t, j in later:
        new = target[j]
        if new != mode:
            if mode in sliding:
                rows.append((since, t, sliding[mode]))
            mode, since = new, t
    if mode in sliding and vf_end == mode:
        rows.append((since, t_end, sliding[mode]))
    return np.array(rows, dtype=float).reshape(-1, 3)
