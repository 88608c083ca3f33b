"""The fuzz cases: a deterministic generator over every command and option.

A :class:`Case` is one run of ``grazing`` with its argument list, its environment, where its standard
output goes, how large a file it may write, and whether its input is certainly wrong (then it must
fail).  :func:`all_cases` makes every case, each with a readable id, the same ones every time (a fixed
seed); :func:`fast_sample` picks the default suite's share.

The families of cases:

- ``value``: one option of a cheap valid command line given a bad or edge value (every option of every
  command: non-numbers, nan, inf, 0, negatives, huge, tiny, empty, wrong separators, unknown names);
- ``missing``: a required option left out; ``unknown``: an option the command does not have;
- ``target``: the command's output option naming every kind of target (a new file, a user's file, a
  file grazing wrote, one a user edited, a read-only file, a folder, a link, a dangling link, a missing
  folder, a device), with and without ``--overwrite``;
- ``model``: every command that takes ``--model`` given each model file (good ones, and each way a user's
  file fails);
- ``stdout``: standard output closed, read for 100 bytes and closed, ``/dev/full``, a file; with and
  without ``PYTHONUNBUFFERED``, from the console script and ``python -m grazing``;
- ``disk``: a command that writes a file, its files limited to a few kB (``RLIMIT_FSIZE``: a full disk);
- ``env``: the environment variables grazing reads, given bad values;
- ``random``: several options mutated at once (seeded).
"""

from __future__ import annotations

import random
from dataclasses import dataclass, replace

SEED = 43
"""The seed of every random choice of the generator (the cases are the same in every run)."""

# --------------------------------------------------------------------------
# Values, by the type of the option


def _vals(bad: list[str], edge: list[str]) -> list[tuple[str, bool]]:
    return [(v, True) for v in bad] + [(v, False) for v in edge]


FLOAT = _vals(
    ["abc", "", "1,2", "0x10", "--json", "1.0.0", "one"],
    [
        "nan",
        "inf",
        "-inf",
        "0",
        "-0",
        "-1",
        "1e308",
        "-1e308",
        "1e-320",
        "1e-300",
        "99999999999999999999",
        "1_000",
        " 0.5",
        "2",
    ],
)
"""A float option's values: (value, certainly invalid)."""

INT = _vals(["abc", "1.5", "", "1e3", "nan", "0x10"], ["99999999999999999999", "0", "-1", "1", "2"])
HUGE_INT = "1000000000"
"""A whole number in range for every size option, too large to compute: refused (memory is checked before
the work), or worked on until a Ctrl-C after :data:`HUGE_WAIT` seconds."""
HUGE_WAIT = 8.0

PAIR = _vals(["1", "a,b", "1,2,3", "", ",", "nan,1", "0,inf", "1,1", "2,1"], ["-1e308,1e308", "0,1e-320"])
STATE = _vals(["", "0", "0;0", "a,b", "nan,0", "inf,0", "0,0,0,0,0"], ["1e308,0", "0.9,0", "-0.5,0.1"])
CHOICE = _vals(["flip", "", "FIRST"], [])
GRID = _vals(["0,2", "3", "a,b", "", "2,2,2", "-1,2"], ["1,1", "1,3"])
SETS = _vals(
    ["eta", "=1", "nope=1", "eta=abc", "eta=nan", "r=2", "theta_hat=200", "eta=", "eta=1=2"],
    ["eta=1e308", "eta=1e-300", "r=0", "r=1", "alpha=0", "beta=0"],
)
PARAM = _vals(["gamma", "", "ETA", "theta_hat_deg"], ["eta", "theta-hat", "theta_hat", "alpha", "beta", "r"])
MODELS = _vals(
    [
        "nope",
        "",
        "smooth.py",
        "smooth.py:",
        "smooth.py:nope",
        "missing.py:model",
        "adir.py:model",
        "random.bin:model",
        "rec.csv:model",
    ],
    ["pendulum", "impact-oscillator", "bouncing-ball", "two-sided-oscillator", "impact-damper"],
)
CASES = _vals(["E", "", "A,B"], ["b", "A", "C", "D", "A-reduced"])
DEG = _vals(["abc", "", "nan", "inf", "1e308"], ["180", "-180", "200", "0", "-10", "89", "179.9", "1e-320"])
R = _vals(["abc", "", "nan", "2", "-0.1", "1.0000001", "inf"], ["0", "1", "1e-320"])
ETA = _vals(["abc", "", "nan", "0", "-1", "inf", "-inf"], ["1e-300", "1e308", "1e-320", "10"])

MODEL_OPTIONS = {
    "--case": CASES,
    "--alpha": FLOAT,
    "--beta": FLOAT,
    "--r": R,
    "--eta": ETA,
    "--theta-hat": DEG,
    "--set": SETS,
    "--model": MODELS,
}
"""The model options of every model command, and their values."""

SWEEP_RUN = {
    "--transient": INT,
    "--periods": INT,
    "--initial": STATE,
    "--chunk-size": INT,
    "--workers": INT,
    "--scheduler": _vals(["", "nonsense", "tcp://", "tcp://127.0.0.1:99999"], []),
    "--timeout": FLOAT,
    "--tol": _vals(["abc", "nan", "0", "-1", "10", "0.01", "inf"], ["1e-300", "1e-3"]),
}


@dataclass(frozen=True)
class Command:
    """A command: a cheap valid argument list, its options and their values, its output option."""

    argv: tuple[str, ...]
    options: dict[str, list[tuple[str, bool]]]
    flags: tuple[str, ...] = ()
    required: tuple[str, ...] = ()
    output: str | None = None
    """The option naming what the command writes (last in ``argv`` if given there)."""
    suffixes: tuple[str, ...] = ()
    """The suffixes its output takes."""
    long_argv: tuple[str, ...] = ()
    """An argument list that works for minutes (for the signal cases)."""


SWEEP = (
    "sweep",
    "--param",
    "eta",
    "--start",
    "0.44",
    "--stop",
    "0.45",
    "--num",
    "2",
    "--periods",
    "3",
    "--transient",
    "3",
    "--workers",
    "1",
)
MAP = (
    "map",
    "--param1",
    "eta",
    "--start1",
    "0.44",
    "--stop1",
    "0.45",
    "--num1",
    "2",
    "--param2",
    "theta-hat",
    "--start2",
    "30",
    "--stop2",
    "31",
    "--num2",
    "2",
    "--periods",
    "3",
    "--transient",
    "3",
    "--workers",
    "1",
)
GRID_BASE = (
    "--model",
    "bouncing-ball",
    "--x-range",
    "0,1",
    "--y-range",
    "-1,1",
    "--periods",
    "3",
    "--transient",
    "3",
    "--workers",
    "1",
)
GRID_OPTIONS = {
    "--x-range": PAIR,
    "--y-range": PAIR,
    "--states": _vals(["0,5", "y,w", "1,1", "0", "", "a,b"], ["y,v", "1,0"]),
    "--fixed": _vals(["w=1", "y=1", "v", "=1", "v=nan"], []),
    "--phase": FLOAT,
    "--transient": INT,
    "--periods": INT,
    "--refine": INT,
    "--cell": FLOAT,
    "--tol": SWEEP_RUN["--tol"],
    "--workers": INT,
}
RANGE_PARAM = {"--param": PARAM, "--start": FLOAT, "--stop": FLOAT}

COMMANDS: dict[str, Command] = {
    "simulate": Command(
        ("simulate", "--transient", "3", "--periods", "3"),
        {
            **MODEL_OPTIONS,
            "--initial": STATE,
            "--transient": INT,
            "--periods": INT,
            "--phase": FLOAT,
            "--points-per-period": INT,
        },
        flags=("--json",),
        output="--trajectory",
        suffixes=(".csv",),
        long_argv=("simulate", "--transient", "100000000", "--periods", "20"),
    ),
    "orbit": Command(
        ("orbit",),
        {**MODEL_OPTIONS, "--period": INT, "--initial": STATE, "--transient": INT},
        flags=("--json",),
        long_argv=("orbit", "--transient", "100000000"),
    ),
    "graze": Command(
        ("graze",),
        {
            **MODEL_OPTIONS,
            "--eta-min": FLOAT,
            "--eta-max": FLOAT,
            "--param": PARAM,
            "--range": PAIR,
            "--stop-name": _vals(["nope", ""], ["stop", "back"]),
            "--initial": STATE,
        },
        flags=("--json",),
    ),
    "graze-curve": Command(
        ("graze-curve", "--start-deg", "30", "--max-step", "0.2"),
        {
            **MODEL_OPTIONS,
            "--start-deg": DEG,
            "--params": _vals(["eta", "eta,eta", "a,b", ""], ["r,alpha"]),
            "--range": PAIR,
            "--start-value": FLOAT,
            "--eta-min": FLOAT,
            "--eta-max": FLOAT,
            "--max-step": FLOAT,
            "--initial": STATE,
        },
        flags=("--json",),
        output="--out",
        suffixes=(".nc",),
        long_argv=("graze-curve", "--max-step", "0.0001"),
    ),
    "continue": Command(
        ("continue", "--param", "eta", "--start", "0.446", "--stop", "0.4455"),
        {
            **MODEL_OPTIONS,
            **RANGE_PARAM,
            "--period": INT,
            "--initial": STATE,
            "--stop-name": _vals(["nope", ""], ["stop"]),
            "--max-step": FLOAT,
        },
        flags=("--json", "--virtual", "--physical", "--switch"),
        required=("--param", "--start", "--stop"),
        output="--out",
        suffixes=(".nc",),
        long_argv=("continue", "--param", "eta", "--start", "0.3", "--stop", "0.9", "--max-step", "1e-6"),
    ),
    "curve": Command(
        (
            "curve",
            "--kind",
            "period-doubling",
            "--param",
            "eta",
            "--start",
            "0.446",
            "--stop",
            "0.44",
            "--param2",
            "theta-hat",
            "--range",
            "39.95,40.05",
        ),
        {
            **MODEL_OPTIONS,
            **RANGE_PARAM,
            "--kind": CHOICE,
            "--param2": PARAM,
            "--range": PAIR,
            "--period": INT,
            "--initial": STATE,
            "--stop-name": _vals(["nope"], []),
            "--max-step": FLOAT,
        },
        flags=("--json",),
        required=("--kind", "--param", "--start", "--stop", "--param2", "--range"),
        output="--out",
        suffixes=(".nc",),
        long_argv=(
            "curve",
            "--kind",
            "period-doubling",
            "--param",
            "eta",
            "--start",
            "0.446",
            "--stop",
            "0.44",
            "--param2",
            "theta-hat",
            "--range",
            "10,70",
            "--max-step",
            "1e-5",
        ),
    ),
    "sweep": Command(
        SWEEP,
        {
            **MODEL_OPTIONS,
            **RANGE_PARAM,
            "--num": INT,
            "--direction": CHOICE,
            "--method": CHOICE,
            "--which": CHOICE,
            **SWEEP_RUN,
        },
        flags=("--json", "--fresh", "--no-lyapunov", "--no-adaptive", "--wait"),
        required=("--param", "--start", "--stop", "--num"),
        output="--out",
        suffixes=(".nc", ".zarr"),
        long_argv=(
            "sweep",
            "--param",
            "eta",
            "--start",
            "0.44",
            "--stop",
            "0.49",
            "--num",
            "4000",
            "--chunk-size",
            "20",
            "--workers",
            "1",
        ),
    ),
    "map": Command(
        MAP,
        {
            **MODEL_OPTIONS,
            "--param1": PARAM,
            "--start1": FLOAT,
            "--stop1": FLOAT,
            "--num1": INT,
            "--param2": PARAM,
            "--start2": FLOAT,
            "--stop2": FLOAT,
            "--num2": INT,
            **SWEEP_RUN,
        },
        flags=("--json", "--fresh", "--no-lyapunov", "--no-adaptive", "--wait"),
        required=("--param1", "--start1", "--stop1", "--num1", "--param2", "--start2", "--stop2", "--num2"),
        output="--out",
        suffixes=(".nc", ".zarr"),
        long_argv=(
            "map",
            "--param1",
            "eta",
            "--start1",
            "0.4",
            "--stop1",
            "0.5",
            "--num1",
            "150",
            "--param2",
            "theta-hat",
            "--start2",
            "30",
            "--stop2",
            "40",
            "--num2",
            "150",
            "--chunk-size",
            "20",
            "--workers",
            "1",
        ),
    ),
    "normal-form": Command(
        ("normal-form",),
        {
            **MODEL_OPTIONS,
            "--which": CHOICE,
            "--eta-min": FLOAT,
            "--eta-max": FLOAT,
            "--param": PARAM,
            "--range": PAIR,
            "--stop-name": _vals(["nope"], []),
            "--initial": STATE,
        },
        flags=("--json", "--check"),
    ),
    "report": Command(
        ("report", "--out", "rep", "--only", "eq"),
        # ("EQ": figure names are read case-insensitively, as case names are (--case b); report.select)
        {"--only": _vals(["fig99", "", "all"], ["EQ", "fig04"]), "--out": _vals([""], [])},
        output="--out",
        suffixes=("",),
        long_argv=("report", "--out", "rep"),
    ),
    "damping": Command(
        ("damping", "--peaks", "3"),
        {
            "--case": CASES,
            "--r": R,
            "--beta": FLOAT,
            "--amplitude": FLOAT,
            "--peaks": INT,
            "--k-hat": INT,
            "--normalisation": CHOICE,
            "--recording": _vals(
                [
                    "missing.csv",
                    "big.csv",
                    "empty.csv",
                    "header.csv",
                    "garbage.csv",
                    "random.bin",
                    "adir.csv",
                    "",
                    "nanrec.csv",
                ],
                [],
            ),
        },
        flags=("--json", "--degrees"),
    ),
    "iso-damping": Command(
        ("iso-damping", "--num", "2", "--relation", "paper"),
        {
            "--damping": FLOAT,
            "--num": INT,
            "--relation": CHOICE,
            "--amplitude": FLOAT,
            "--peaks": INT,
            "--normalisation": CHOICE,
        },
        flags=("--json",),
        output="--out",
        suffixes=(".csv",),
        long_argv=("iso-damping", "--num", "100000"),
    ),
    "fit": Command(
        ("fit", "--theta-hat", "40", "--eta-graze", "0.445"),
        {"--theta-hat": DEG, "--eta-graze": ETA, "--damping": FLOAT, "--alpha": FLOAT, "--relation": CHOICE},
        flags=("--json",),
    ),
    "analyze": Command(
        ("analyze", "rec.csv"),
        {
            "--forcing-hz": FLOAT,
            "--phase": FLOAT,
            "--cutoff-hz": FLOAT,
            "--cutoff-multiple": FLOAT,
            "--max-period": INT,
            "--noise": FLOAT,
            "--case": CASES,
            "--model-points": INT,
            "--theta-hat": DEG,
        },
        flags=("--json", "--degrees"),
        output="--plot",
        suffixes=(".png",),
    ),
    "synthesize": Command(
        (
            "synthesize",
            "--eta",
            "0.446",
            "--periods",
            "8",
            "--transient",
            "0",
            "--sample-rate",
            "100",
            "--out",
            "syn.csv",
        ),
        {
            "--eta": ETA,
            "--theta-hat": DEG,
            "--case": CASES,
            "--periods": INT,
            "--transient": INT,
            "--sample-rate": FLOAT,
            "--noise": FLOAT,
            "--seed": INT,
        },
        flags=("--json",),
        required=("--eta", "--out"),
        output="--out",
        suffixes=(".csv",),
        long_argv=(
            "synthesize",
            "--eta",
            "0.446",
            "--transient",
            "10000000",
            "--periods",
            "8",
            "--out",
            "x.csv",
        ),
    ),
    "basins": Command(
        ("basins", *GRID_BASE, "--num", "2,2"),
        {**MODEL_OPTIONS, **GRID_OPTIONS, "--num": GRID, "--chunk-size": INT},
        flags=("--json", "--no-lyapunov", "--wait"),
        required=("--x-range", "--y-range", "--num"),
        output="--out",
        suffixes=(".nc", ".zarr"),
        long_argv=(
            "basins",
            "--model",
            "bouncing-ball",
            "--x-range",
            "0,1",
            "--y-range",
            "-1,1",
            "--num",
            "300,300",
            "--chunk-size",
            "50",
            "--workers",
            "1",
            "--out",
            "b.zarr",
        ),
    ),
    "attractors": Command(
        (
            "attractors",
            *GRID_BASE,
            "--param",
            "amplitude",
            "--start",
            "0.5",
            "--stop",
            "0.8",
            "--num",
            "2",
            "--num-grid",
            "2,2",
        ),
        {**MODEL_OPTIONS, **GRID_OPTIONS, **RANGE_PARAM, "--num": INT, "--num-grid": GRID, "--seeds": INT},
        flags=("--json", "--no-lyapunov"),
        required=("--param", "--start", "--stop", "--num", "--x-range", "--y-range", "--num-grid"),
        output="--out",
        suffixes=(".nc",),
        long_argv=(
            "attractors",
            "--model",
            "bouncing-ball",
            "--param",
            "amplitude",
            "--start",
            "0.5",
            "--stop",
            "0.8",
            "--num",
            "200",
            "--x-range",
            "0,1",
            "--y-range",
            "-1,1",
            "--num-grid",
            "20,20",
            "--workers",
            "1",
        ),
    ),
    "explore": Command(
        ("explore", "--param", "eta", "--range", "0.44,0.45", "--num", "2", "--no-browser", "--port", "0"),
        {
            **MODEL_OPTIONS,
            "--param": PARAM,
            "--params": _vals(["eta", "eta,eta", "a,b", ""], ["eta,theta-hat"]),
            "--range": PAIR,
            "--num": INT,
            "--component": _vals(["x", "", "nope"], ["theta", "dtheta"]),
            "--port": _vals(["70000", "-1", "abc", ""], ["0"]),
        },
    ),
}
"""Every command of ``grazing``: a cheap valid call, its options and their values."""

LONG_COMMANDS = [name for name, c in COMMANDS.items() if c.long_argv]
"""The commands that may work for long (the signal cases)."""

# --------------------------------------------------------------------------
# Output targets


def targets(suffix: str) -> list[tuple[str, str, bool]]:
    """``(label, path, certainly refused)`` for an output of ``suffix`` ("" for a folder)."""
    if suffix == "":
        return [
            ("new", "rep", False),
            ("user-folder", "myreport", True),
            ("empty-folder", "emptydir", False),
            ("missing-parents", "a/b/c", True),
            ("file", "notes.csv", True),
            ("link", "link.csv", True),
            ("empty", "", True),
            ("grazings-zarr", "ours.zarr", True),
        ]
    if suffix == ".zarr":
        return [
            ("new", "new.zarr", False),
            ("grazings", "ours.zarr", False),
            ("user", "user.zarr", True),
            ("folder", "adir.zarr", True),
            ("missing-folder", "nodir/new.zarr", True),
        ]
    kind = suffix[1:]
    user = {".nc": "mine.nc", ".csv": "notes.csv", ".png": "mine.png"}[suffix]
    return [
        ("new", f"new{suffix}", False),
        ("user", user, None),  # refused without --overwrite, replaced with it
        ("grazings", f"ours{suffix}", False),
        ("edited", f"edited{suffix}", None),
        *([("edited-attrs", "edited-attrs.nc", None)] if suffix == ".nc" else []),
        ("readonly", f"readonly{suffix}", None),
        ("folder", f"adir{suffix}", True),
        ("link", f"link{suffix}", None),
        ("dangling-link", f"dangling{suffix}", False),
        ("missing-folder", f"nodir/new{suffix}", True),
        ("device", "/dev/null", True),
        ("wrong-suffix", "new.txt", True),
        ("binary", "random.bin", True),
        ("empty", "", True),
        ("dot", ".", True),
        ("hidden", f".hidden{suffix}", False),
        ("spaces", f"a name with spaces {kind}{suffix}", False),
    ]


REPORT_REFUSED = ("missing-parents", "file", "link", "empty")
"""The folder targets refused whatever the options (a report with --overwrite; a folder of recordings)."""

# --------------------------------------------------------------------------
# Cases


STDOUT_KINDS = ("pipe", "closed", "head", "full", "file")
"""Where a process's standard output goes: a pipe read to its end, a pipe closed before it starts, a pipe
read for 100 bytes and closed, ``/dev/full``, a regular file."""


@dataclass(frozen=True)
class Case:
    """One run of ``grazing``: what to run, where its output goes, and what it must do.

    ``process``: run as a process (else in this process, through :func:`grazing.cli.main`);
    ``entry``: ``"console"`` (the installed script's entry point) or ``"module"`` (``python -m grazing``);
    ``invalid``: the input is certainly wrong, so the command must fail;
    ``fsize``: the largest file the process may write (``RLIMIT_FSIZE``), None for no limit.
    """

    id: str
    argv: tuple[str, ...]
    family: str
    command: str
    invalid: bool = False
    process: bool = False
    entry: str = "console"
    env: tuple[tuple[str, str], ...] = ()
    stdout: str = "pipe"
    fsize: int | None = None
    timeout: float = 120.0
    interrupt_after: float | None = None
    """If the process still runs after this many seconds, it gets a Ctrl-C (SIGINT to its group): working
    on a huge size, it must then end as after any Ctrl-C."""

    @property
    def overwrite(self) -> bool:
        """Whether ``--overwrite`` was given."""
        return "--overwrite" in self.argv

    def outputs(self) -> list[str]:
        """The paths the command was told to write (its output option's values)."""
        cmd = COMMANDS[self.command]
        if cmd.output is None:
            return []
        names = {cmd.output}
        return [self.argv[i + 1] for i in range(1, len(self.argv) - 1) if self.argv[i] in names]


def with_option(argv: tuple[str, ...], option: str, value: str | None) -> tuple[str, ...]:
    """``argv`` with ``option`` given ``value`` (replacing its value there if present; a flag if None)."""
    if value is None:
        return (*argv, option) if option not in argv else argv
    if option in argv and option not in ("--set", "--fixed", "--eta", "--only", "--k-hat"):
        i = argv.index(option)
        return (*argv[: i + 1], value, *argv[i + 2 :])
    return (*argv, option, value)


def without_option(argv: tuple[str, ...], option: str) -> tuple[str, ...]:
    """``argv`` without ``option`` and its value."""
    if option not in argv:
        return argv
    i = argv.index(option)
    return (*argv[:i], *argv[i + 2 :])


def _value_cases(name: str, cmd: Command) -> list[Case]:
    out = []
    for option, values in cmd.options.items():
        for k, (value, invalid) in enumerate(values):
            argv = with_option(cmd.argv, option, value)
            out.append(Case(f"{name}/value{option}={value!r}#{k}", argv, "value", name, invalid))
    # every size in range but far too large: refused before the work (memory), or the work stopped
    for option, values in cmd.options.items():
        if values is INT and option not in ("--period", "--max-period", "--seed", "--workers", "--k-hat"):
            argv = with_option(cmd.argv, option, HUGE_INT)
            out.append(
                Case(f"{name}/huge{option}", argv, "huge", name, process=True, interrupt_after=HUGE_WAIT)
            )
    for flag in cmd.flags:
        out.append(Case(f"{name}/flag{flag}", with_option(cmd.argv, flag, None), "flag", name))
    return out


def _structure_cases(name: str, cmd: Command) -> list[Case]:
    out = [
        Case(f"{name}/unknown-option", (*cmd.argv, "--nonsense", "1"), "unknown", name, True),
        Case(f"{name}/stray-argument", (*cmd.argv, "stray"), "unknown", name, True),
        Case(f"{name}/help", (name, "--help"), "help", name),
        Case(f"{name}/option-without-value", (*cmd.argv, next(iter(cmd.options))), "unknown", name, True),
    ]
    for option in cmd.required:
        out.append(Case(f"{name}/missing{option}", without_option(cmd.argv, option), "missing", name, True))
    return out


def _target_cases(name: str, cmd: Command) -> list[Case]:
    out = []
    if cmd.output is None:
        return out
    for suffix in cmd.suffixes:
        for label, path, refused in targets(suffix):
            if name == "synthesize" and label == "dot":
                continue  # (a folder: a folder of recordings, below)
            for overwrite in (False, True):
                argv = with_option(cmd.argv, cmd.output, path)
                if overwrite:
                    argv = (*argv, "--overwrite")
                invalid = bool(refused) if refused is not None else not overwrite
                if name == "report" and overwrite:  # (a folder not of grazing's: its report files replaced)
                    invalid = label in REPORT_REFUSED
                if suffix == ".zarr" and overwrite:
                    invalid = True  # (--overwrite is not used with a Zarr store)
                tag = "+overwrite" if overwrite else ""
                out.append(
                    Case(f"{name}/target{suffix or '-folder'}-{label}{tag}", argv, "target", name, invalid)
                )
    if name == "synthesize":  # a folder of recordings: several --eta
        base = with_option(cmd.argv, "--eta", "0.43")
        for label, path, _refused in targets(""):
            argv = with_option(base, "--out", path)
            out.append(Case(f"{name}/target-folder-{label}", argv, "target", name, label in REPORT_REFUSED))
    return out


MODEL_COMMANDS = [n for n, c in COMMANDS.items() if "--model" in c.options]

MODEL_FILE_SPECS = {
    "smooth.py:model": False,
    "prints.py:model": False,
    "nocd.py:nocd": False,
    "nonsmooth.py:abs_model": True,
    "baddefault.py:bad": True,
    "exits.py:model": True,
    "exitstr.py:model": True,
    "syntax.py:model": True,
    "raises.py:model": True,
    "callraises.py:model": True,
    "recursion.py:model": True,
    "notmodel.py:model": True,
    "base.py:model": True,
    "basecall.py:model": True,
    "genexit.py:model": True,
    "kbi.py:model": True,
}
"""Each model file's ``--model`` value, and whether it certainly fails to load."""

USER_MODEL_ARGS: dict[str, tuple[str, ...]] = {
    "simulate": ("simulate", "--transient", "3", "--periods", "3"),
    "orbit": ("orbit", "--transient", "20"),
    "graze": ("graze", "--param", "w", "--range", "0.5,2"),
    "graze-curve": ("graze-curve", "--params", "w,r", "--range", "0.5,2", "--start-value", "0.8"),
    "continue": ("continue", "--param", "w", "--start", "1.2", "--stop", "1.19"),
    "curve": (
        "curve",
        "--kind",
        "fold",
        "--param",
        "w",
        "--start",
        "1.2",
        "--stop",
        "1.1",
        "--param2",
        "r",
        "--range",
        "0.7,0.9",
    ),
    "sweep": (
        "sweep",
        "--param",
        "w",
        "--start",
        "1.2",
        "--stop",
        "1.3",
        "--num",
        "2",
        "--periods",
        "3",
        "--transient",
        "3",
        "--workers",
        "1",
    ),
    "map": (
        "map",
        "--param1",
        "w",
        "--start1",
        "1.2",
        "--stop1",
        "1.3",
        "--num1",
        "2",
        "--param2",
        "r",
        "--start2",
        "0.5",
        "--stop2",
        "0.6",
        "--num2",
        "2",
        "--periods",
        "3",
        "--transient",
        "3",
        "--workers",
        "1",
    ),
    "normal-form": ("normal-form", "--param", "w", "--range", "0.5,2"),
    "basins": (
        "basins",
        "--x-range",
        "-1,0.4",
        "--y-range",
        "-1,1",
        "--num",
        "2,2",
        "--periods",
        "3",
        "--transient",
        "3",
        "--workers",
        "1",
    ),
    "attractors": (
        "attractors",
        "--param",
        "w",
        "--start",
        "1.2",
        "--stop",
        "1.3",
        "--num",
        "2",
        "--x-range",
        "-1,0.4",
        "--y-range",
        "-1,1",
        "--num-grid",
        "2,2",
        "--periods",
        "3",
        "--transient",
        "3",
        "--workers",
        "1",
    ),
    "explore": ("explore", "--param", "w", "--range", "1,1.3", "--num", "2", "--no-browser", "--port", "0"),
}
"""Each model command, cheap and valid for the user model of the model files (parameters w and r)."""


def _model_cases() -> list[Case]:
    out = []
    for name in MODEL_COMMANDS:
        for spec, fails in MODEL_FILE_SPECS.items():
            argv = (*USER_MODEL_ARGS[name], "--model", spec)
            out.append(Case(f"{name}/model={spec}", argv, "model", name, fails))
    return out


def _stdout_cases() -> list[Case]:
    out = []
    for name, cmd in COMMANDS.items():
        if name in ("explore", "report"):
            continue
        argv = cmd.argv if "--json" not in cmd.flags else (*cmd.argv, "--json")
        for kind in STDOUT_KINDS:
            for unbuffered in (False, True):
                for entry in ("console", "module"):
                    env = (("PYTHONUNBUFFERED", "1"),) if unbuffered else ()
                    label = f"{name}/stdout-{kind}{'-unbuffered' if unbuffered else ''}-{entry}"
                    out.append(
                        Case(label, argv, "stdout", name, process=True, entry=entry, env=env, stdout=kind)
                    )
    return out


def _disk_cases() -> list[Case]:
    out = []
    for name, cmd in COMMANDS.items():
        if cmd.output is None or name == "report":
            continue
        for suffix in cmd.suffixes:
            path = "new" + suffix if suffix else "rep"
            argv = with_option(cmd.argv, cmd.output, path)
            if name in ("sweep", "map", "basins") and suffix == ".nc":
                argv = with_option(argv, "--workers", "1")
            for limit in (0, 100, 4096):
                for unbuffered in (False, True):
                    env = (("PYTHONUNBUFFERED", "1"),) if unbuffered else ()
                    label = f"{name}/full-disk{suffix}-{limit}B{'-unbuffered' if unbuffered else ''}"
                    out.append(Case(label, argv, "disk", name, process=True, env=env, fsize=limit))
    return out


ENV_VALUES = {
    "GRAZING_MAX_MEMORY": [
        ("abc", True),
        ("", False),
        ("1e400", True),
        ("0", False),
        ("-1G", False),
        ("1K", False),
        ("8G", False),
        ("1e3", False),
    ],
    "GRAZING_CACHE_DIR": [("rec.csv", True), ("random.bin", True), ("/dev/null", True), ("", False)],
}
"""Environment variables grazing reads, and values given them (an existing folder of compiled kernels is
the default; a new one compiles for a minute: the signal cases)."""


MEMORY_CHECKED = ("simulate", "sweep", "basins")
"""Of the commands the env cases run, those that estimate their memory before the work and so read
``GRAZING_MAX_MEMORY`` (README, "Limits"; ``grazing.cli.limits``): a bad value fails them.  ``orbit``'s
result is small and fixed; it never reads the variable and may ignore a bad value, as a program ignores
any variable it does not use."""


def _env_cases() -> list[Case]:
    out = []
    for var, values in ENV_VALUES.items():
        for value, invalid in values:
            for name in ("simulate", "sweep", "basins", "orbit"):
                argv = COMMANDS[name].argv
                label = f"{name}/env-{var}={value!r}"
                read = var != "GRAZING_MAX_MEMORY" or name in MEMORY_CHECKED
                env = ((var, value),)
                out.append(Case(label, argv, "env", name, invalid and read, process=True, env=env))
    return out


def _random_cases(n: int, rng: random.Random) -> list[Case]:
    """``n`` cases with two to four options mutated at once (values of any class)."""
    out = []
    names = sorted(COMMANDS)
    for k in range(n):
        name = names[k % len(names)]
        cmd = COMMANDS[name]
        argv = cmd.argv
        for _ in range(rng.randint(2, 4)):
            option = rng.choice(sorted(cmd.options) + list(cmd.flags))
            if option in cmd.flags:
                argv = with_option(argv, option, None)
            else:
                argv = with_option(argv, option, rng.choice(cmd.options[option])[0])
        out.append(Case(f"{name}/random-{k}", argv, "random", name))
    return out


def all_cases() -> list[Case]:
    """Every case, in a fixed order with unique ids."""
    rng = random.Random(SEED)
    cases: list[Case] = []
    for name, cmd in COMMANDS.items():
        cases += _value_cases(name, cmd)
        cases += _structure_cases(name, cmd)
        cases += _target_cases(name, cmd)
    cases += _model_cases()
    cases += _stdout_cases()
    cases += _disk_cases()
    cases += _env_cases()
    cases += _random_cases(400, rng)
    # a sample of the in-process cases run again as processes (the real entry point, end to end)
    inproc = [c for c in cases if not c.process]
    for c in rng.sample(inproc, 150):
        cases.append(replace(c, id=c.id + "@process", process=True))
    ids = [c.id for c in cases]
    assert len(ids) == len(set(ids)), [i for i in ids if ids.count(i) > 1][:5]
    return cases


FAST_PER_FAMILY = {
    "value": 170, "flag": 12, "huge": 2, "unknown": 10, "missing": 8, "help": 3, "target": 50, "model": 30,
    "stdout": 16, "disk": 6, "env": 4, "random": 15,
}  # fmt: skip
"""How many cases of each family the default suite runs (the rest: ``make test-all``)."""


def fast_sample(cases: list[Case]) -> list[Case]:
    """The default suite's cases: a fixed, seeded share of every family (and every command)."""
    rng = random.Random(SEED + 1)
    chosen: list[Case] = []
    for family, n in FAST_PER_FAMILY.items():
        members = [c for c in cases if c.family == family and not c.id.endswith("@process")]
        chosen += rng.sample(members, min(n, len(members)))
    return chosen
