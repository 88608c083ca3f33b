"""Grazing normal form: Nordmark's discontinuity map and the predictions it makes."""

from grazing.normalform.discontinuity import GrazingNormalForm, normal_form_at, zdm_direction

__all__ = ["GrazingNormalForm", "normal_form_at", "zdm_direction"]
