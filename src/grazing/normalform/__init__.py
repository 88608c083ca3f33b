"""Grazing normal form: Nordmark's discontinuity map and the predictions it makes."""

from grazing.normalform.discontinuity import (
    GrazingNormalForm,
    find_grazing_point,
    normal_form_at,
    zdm_direction,
)
from grazing.normalform.prediction import Observation, Prediction, observe, predict, predicted_windows

__all__ = [
    "GrazingNormalForm",
    "Observation",
    "Prediction",
    "find_grazing_point",
    "normal_form_at",
    "observe",
    "predict",
    "predicted_windows",
    "zdm_direction",
]
