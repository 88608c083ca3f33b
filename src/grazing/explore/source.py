"""Where the explored model comes from, and the Python and command-line text that make it again.

The explorer's "copy as code" writes a model back as text: a built-in model by its
constructor (``grazing.models.pendulum()``), a model file by ``FILE.py:OBJECT``, each
with every parameter value set explicitly, so that the text reproduces the view
whatever the defaults.
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass
from pathlib import Path

from grazing.core.model import HybridModel
from grazing.models import BUILT_IN

__all__ = ["ModelSource"]


@dataclass(frozen=True)
class ModelSource:
    """How the explored model is made.

    Attributes
    ----------
    spec
        What ``--model`` takes: a built-in model's name (``"pendulum"``) or
        ``"FILE.py:OBJECT"`` (the file's path made absolute, so that the text works
        from any folder); None for a model object given in Python that is not a
        built-in model (its code then starts from a variable ``model``).

    Examples
    --------
    >>> import grazing
    >>> ModelSource.of(grazing.models.impact_oscillator()).spec
    'impact-oscillator'
    >>> ModelSource.of(grazing.models.pendulum(), "tests/m.py:model").spec.endswith("tests/m.py:model")
    True
    """

    spec: str | None = None

    @classmethod
    def of(cls, model: HybridModel, spec: str | None = None) -> ModelSource:
        """The source of ``model``: ``spec`` as ``--model`` gave it, else a built-in model recognised."""
        if spec is not None:
            if spec in BUILT_IN:
                return cls(spec)
            path, _, name = spec.rpartition(":")
            return cls(f"{Path(path).resolve()}:{name}")
        built_in = BUILT_IN.get(model.name)
        if built_in is not None and getattr(built_in(), "_def", None) is getattr(model, "_def", False):
            return cls(model.name)
        return cls(None)

    @property
    def built_in(self) -> bool:
        return self.spec is not None and self.spec in BUILT_IN

    def python_lines(self, model: HybridModel) -> list[str]:
        """Lines of Python defining ``model`` (after ``import grazing``), every parameter set."""
        values = ", ".join(f"{name}={float(value)!r}" for name, value in model.params.items())
        if self.spec is None:
            return [
                "# model: the HybridModel given to the explorer (a variable of your own)",
                f"model = model.with_params({values})",
            ]
        if self.built_in:
            return [f"model = grazing.models.{BUILT_IN[self.spec].__name__}().with_params({values})"]
        path, _, name = self.spec.rpartition(":")
        return [
            f"loaded = runpy.run_path({path!r})[{name!r}]",
            "model = loaded if isinstance(loaded, grazing.HybridModel) else loaded()",
            f"model = model.with_params({values})",
        ]

    @property
    def python_imports(self) -> list[str]:
        """The imports :meth:`python_lines` needs."""
        return ["import runpy"] if self.spec is not None and not self.built_in else []

    def cli_args(self, model: HybridModel, varied: tuple[str, ...] = ()) -> list[str]:
        """``--model SPEC --set NAME=VALUE ...`` for every parameter but the ``varied`` ones (display units).

        Raises
        ------
        ValueError
            For a model given as an object (no ``--model`` can name it).
        """
        if self.spec is None:
            raise ValueError("a model given as a Python object has no --model: save it in a file")
        args = ["--model", self.spec]
        for par in model.parameters:
            if par.name not in varied:
                args += ["--set", f"{par.name}={par.to_display(model.params[par.name])!r}"]
        return args


def command_line(args: list[str]) -> str:
    """``grazing ARGS...`` quoted for a POSIX shell.

    Examples
    --------
    >>> command_line(["simulate", "--set", "eta=0.446", "--model", "/tmp/my model.py:m"])
    "grazing simulate --set eta=0.446 --model '/tmp/my model.py:m'"
    """
    return shlex.join(["grazing", *args])
