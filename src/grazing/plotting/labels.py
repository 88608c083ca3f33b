"""Labels for plots, from the metadata of models and sweep datasets (never from parameter names).

A :class:`~grazing.core.model.Parameter` carries its display symbol, unit and
whether it is an angle (shown in degrees); a model its state labels and
units and how to print time; a sweep dataset copies them (parameter
coordinates' ``symbol``/``units``/``angle`` attributes, the dataset's
``state_labels``/``state_units``/``time_label``/``forcing_period``).
"""

from __future__ import annotations

import json
import math
from typing import Any

from grazing.core.model import Parameter


def angle_scale(degrees: bool) -> float:
    """The factor from radians to the axis unit."""
    return 180.0 / math.pi if degrees else 1.0


def param_label(parameter: Parameter, degrees: bool = True) -> str:
    """Axis label for a model parameter: ``"η"``, ``"θ̂ (degrees)"``, ``"θ̂ (rad)"``, ``"σ (m)"``.

    Parameters
    ----------
    parameter
        The model's parameter (its symbol and unit).
    degrees
        Show an angle in degrees.

    Returns
    -------
    str
        Its symbol, with its unit in brackets when it has one.

    Examples
    --------
    >>> import grazing
    >>> m = grazing.models.pendulum("B")
    >>> param_label(m.parameter("eta")), param_label(m.parameter("theta_hat"))
    ('η', 'θ̂ (degrees)')
    >>> param_label(m.parameter("theta_hat"), degrees=False)
    'θ̂ (rad)'
    """
    unit = parameter.display_unit if degrees else parameter.unit
    unit = "degrees" if unit == "deg" else unit
    return f"{parameter.label} ({unit})" if unit else parameter.label


def dataset_parameter(ds: Any, name: str) -> Parameter:
    """The metadata of a sweep dataset's parameter coordinate ``name``, as a :class:`Parameter`."""
    attrs = ds[name].attrs if name in ds.variables else {}
    return Parameter(
        name, 0.0, symbol=str(attrs.get("symbol", name)), unit=str(attrs.get("units", "")),
        angle=bool(attrs.get("angle", 0)), description=str(attrs.get("long_name", "")),
    )  # fmt: skip


def param_scale(parameter: Parameter, degrees: bool) -> float:
    """The factor from the parameter's model unit to the axis unit."""
    return 180.0 / math.pi if degrees and parameter.angle else 1.0


def swept_parameter(ds: Any) -> str:
    """The swept parameter's name (the first one for a two-parameter map)."""
    return str(ds.attrs.get("params", "value")).split(",")[0]


def state_unit(unit: str, degrees: bool) -> str:
    """The axis unit of a state with model unit ``unit``: radians become degrees when asked.

    Examples
    --------
    >>> state_unit("rad", True), state_unit("rad per unit time", True), state_unit("m", True)
    ('degrees', 'degrees per unit time', 'm')
    """
    if degrees and (unit == "rad" or unit.startswith("rad ") or unit.startswith("rad/")):
        return "degrees" + unit[3:]
    return unit


def state_scale(unit: str, degrees: bool) -> float:
    """The factor from a state's model unit to its axis unit."""
    return angle_scale(degrees) if state_unit(unit, degrees) != unit else 1.0


def with_unit(name: str, unit: str) -> str:
    return f"{name} ({unit})" if unit else name


def dataset_states(ds: Any) -> tuple[list[str], list[str]]:
    """State labels and units stored with a sweep dataset (the component names, if none)."""
    names = [str(c) for c in ds["component"].values] if "component" in ds.coords else []
    labels = json.loads(ds.attrs["state_labels"]) if "state_labels" in ds.attrs else names
    units = json.loads(ds.attrs["state_units"]) if "state_units" in ds.attrs else [""] * len(labels)
    return labels, units


def period_text(period: float) -> str:
    """``"2π"`` for a period of 2 pi, else ``"T"``."""
    return "2π" if math.isclose(period, 2 * math.pi) else "T"
