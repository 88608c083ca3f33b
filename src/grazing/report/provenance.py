"""Where and with what a report was built: the commit, the versions, the machine.

Examples
--------
>>> p = collect()
>>> {"python", "numpy", "scipy", "numba", "llvmlite", "sympy", "xarray"} <= set(p.versions)
True
>>> p.cores >= 1 and p.vector_width in (2, 4, 8) and p.dirty == p.commit.endswith("+dirty")
True
"""

from __future__ import annotations

import os
import platform
import subprocess
from dataclasses import asdict, dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

import grazing

PACKAGES = ("numpy", "scipy", "numba", "llvmlite", "sympy", "xarray", "matplotlib", "h5netcdf")
"""The packages whose versions the page states (with Python and grazing)."""


@dataclass(frozen=True)
class Provenance:
    """The build's provenance.

    Attributes
    ----------
    commit
        ``git rev-parse HEAD`` of the source tree (empty when it is not a git checkout),
        with ``+dirty`` when the tree has uncommitted changes.
    versions
        ``{"python": ..., "grazing": ..., "numpy": ..., ...}``.
    cpu
        The CPU model.
    cores
        Logical cores usable by this process.
    system
        Operating system and machine.
    vector_width
        Doubles per vector register the compiled kernels use on this processor
        (:func:`grazing.engine.llvmgen.lane_width`: 8 with AVX-512, 4 with AVX, else 2).
    dirty
        True when the source tree has uncommitted changes under ``src/`` (the build is then not
        exactly the commit).
    """

    commit: str
    versions: dict[str, str] = field(default_factory=dict)
    cpu: str = ""
    cores: int = 1
    system: str = ""
    vector_width: int = 0
    dirty: bool = False

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


def source_root() -> Path:
    """The directory above the ``grazing`` package's source (the repository, for an editable install)."""
    return Path(grazing.__file__).resolve().parents[2]


def git_commit(root: Path | None = None) -> str:
    """The commit of the source tree, ``+dirty`` if it has uncommitted changes; empty if not in git."""
    cwd = root or source_root()
    try:
        head = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=cwd, capture_output=True, text=True, timeout=10, check=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no", "--", "src"],
            cwd=cwd,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""
    return head + ("+dirty" if dirty else "")


def cpu_model() -> str:
    """The CPU's model name (from ``/proc/cpuinfo`` on Linux, else :func:`platform.processor`)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def usable_cores() -> int:
    """Logical cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def versions() -> dict[str, str]:
    """Versions of Python, grazing and :data:`PACKAGES`."""
    out = {"python": platform.python_version(), "grazing": grazing.__version__}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


def vector_width() -> int:
    """Doubles per vector register of this processor as the kernels use it (0 when LLVM is unavailable)."""
    try:
        from grazing.engine.llvmgen import lane_width

        return lane_width()
    except Exception:  # pragma: no cover - stated as unknown, never fatal to a report
        return 0


def collect() -> Provenance:
    """The provenance of a build on this machine from this source tree."""
    commit = git_commit()
    return Provenance(
        commit=commit,
        dirty=commit.endswith("+dirty"),
        vector_width=vector_width(),
        versions=versions(),
        cpu=cpu_model(),
        cores=usable_cores(),
        system=platform.platform(terse=True),
    )
