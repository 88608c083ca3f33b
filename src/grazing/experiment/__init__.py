"""Experiment tools: damping, recordings, signal pipeline, fitting, synthetic data (paper section 2).

The paper's experimental side, linked to the model:

* :mod:`~grazing.experiment.damping` -- free decay of the model, the
  logarithmic-decrement estimator of eq. 1 (normalised so that eq. 6 holds),
  the equal-damping curve of fig 4(b), damping of a recorded free decay;
* :mod:`~grazing.experiment.fit` -- the paper's fit of ``(r, beta)``: the point
  of the equal-damping curve whose primary grazing happens at the observed
  ``eta``;
* :mod:`~grazing.experiment.recording` -- loading and validating recorded
  angle CSV files, the forcing's timing (trigger pulses or a frequency);
* :mod:`~grazing.experiment.signal` -- Butterworth filtering, stroboscopic
  samples, delay embedding, period detection on noisy samples;
* :mod:`~grazing.experiment.diagram` -- experimental bifurcation diagrams from
  a folder of recordings, beside the model's sweep;
* :mod:`~grazing.experiment.synthetic` -- synthetic rig recordings simulated
  from the model (the paper's measured data are not public);

Examples
--------
>>> from grazing.experiment import model_damping
>>> round(model_damping(1.0, 0.068).damping, 4)
0.0689
"""

from grazing.experiment.apparatus import PAPER_RIG, Apparatus
from grazing.experiment.damping import (
    PAPER_POINTS,
    DampingEstimate,
    FreeDecay,
    IsoDampingCurve,
    beta_for_damping,
    free_decay,
    iso_damping,
    linear_damping,
    log_decrement,
    model_damping,
    paper_relation,
    r_for_damping,
    recorded_damping,
)
from grazing.experiment.diagram import ExperimentDiagram, load_diagram, model_sweep
from grazing.experiment.fit import FitResult, fit_parameters, grazing_eta
from grazing.experiment.recording import (
    ForcingClock,
    Recording,
    RecordingError,
    forcing_clock,
    from_arrays,
    load_recording,
)
from grazing.experiment.signal import (
    Analysis,
    analyze_recording,
    delay_embedding,
    detect_period_noisy,
    estimate_noise,
    lowpass,
    stroboscopic,
)
from grazing.experiment.synthetic import (
    synthetic_free_decay,
    synthetic_recording,
    synthetic_sweep,
    write_recording,
)

__all__ = [
    "PAPER_POINTS",
    "PAPER_RIG",
    "Analysis",
    "Apparatus",
    "DampingEstimate",
    "ExperimentDiagram",
    "FitResult",
    "ForcingClock",
    "FreeDecay",
    "IsoDampingCurve",
    "Recording",
    "RecordingError",
    "analyze_recording",
    "beta_for_damping",
    "delay_embedding",
    "detect_period_noisy",
    "estimate_noise",
    "fit_parameters",
    "forcing_clock",
    "free_decay",
    "from_arrays",
    "grazing_eta",
    "iso_damping",
    "linear_damping",
    "load_diagram",
    "load_recording",
    "log_decrement",
    "lowpass",
    "model_damping",
    "model_sweep",
    "paper_relation",
    "r_for_damping",
    "recorded_damping",
    "stroboscopic",
    "synthetic_free_decay",
    "synthetic_recording",
    "synthetic_sweep",
    "write_recording",
]
