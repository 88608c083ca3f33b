"""Grazing normal form: Nordmark's discontinuity map and the predictions it makes, and the map of a
switching surface without a reset."""

from grazing.normalform.discontinuity import (
    GrazingNormalForm,
    find_grazing_point,
    normal_form_at,
    zdm_direction,
)
from grazing.normalform.prediction import Observation, Prediction, observe, predict, predicted_windows
from grazing.normalform.switching import SwitchingMap, switching_map_at

__all__ = [
    "GrazingNormalForm",
    "Observation",
    "Prediction",
    "SwitchingMap",
    "find_grazing_point",
    "normal_form_at",
    "observe",
    "predict",
    "predicted_windows",
    "switching_map_at",
    "zdm_direction",
]
