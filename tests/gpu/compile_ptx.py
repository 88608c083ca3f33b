"""Compile the sweep kernel of built-in models to PTX for a GPU, without a GPU (a manual check).

Needs numba-cuda and NVVM (the ``nvidia-cuda-nvcc-cu12`` and ``nvidia-cuda-nvrtc-cu12`` wheels; their
``lib`` folders on ``LD_LIBRARY_PATH``).  numba compiles a device function for the current device's
compute capability; with no device, that is taken to be ``--cc`` (9.0: an H100).  Typing, lowering and
NVVM's compilation to PTX are the device's: a construct the device cannot compile fails here.

    python tests/gpu/compile_ptx.py pendulum impact_oscillator bouncing_ball rocking_block --cc 9.0 --zdm

Each model's kernel is compiled twice: without and with Lyapunov exponents (``build_kernel``'s
``lyapunov``); with ``--zdm`` twice more, with the discontinuity map standing for the first stop's impacts
(``build_kernel``'s ``zdm_stop``).  With ``--ptxas PATH`` (a CUDA toolkit's ``ptxas`` as new as the NVVM)
the PTX is also assembled for the device (``ptxas -v``): the registers each thread takes, its stack frame
and the bytes it spills, what fixes how many threads an SM holds at once (an H100 or H200: 65,536
registers and at most 2,048 threads per SM).
"""

from __future__ import annotations

import argparse
import re
import subprocess
import tempfile
import time
import types as pytypes

import grazing
from grazing.engine.codegen import taylor_order
from grazing.gpu.kernel import build_kernel, keep_rows
from grazing.gpu.model import model_functions


def kernel_signature() -> tuple[object, ...]:
    """The argument types of the sweep kernel (:func:`grazing.gpu.kernel.build_kernel`)."""
    from numba import types

    f8, i8 = types.float64, types.int64

    def array(t: object, nd: int) -> object:
        return types.Array(t, nd, "C")

    return (array(i8, 2), array(i8, 1), array(f8, 2), array(f8, 2), array(i8, 1), array(i8, 1),
            array(f8, 2), array(f8, 1), array(f8, 1), array(f8, 1), array(f8, 3), array(i8, 2),
            array(f8, 1), array(i8, 1), array(f8, 2), array(f8, 1), array(i8, 1), array(i8, 1),
            array(f8, 3), array(i8, 1), array(f8, 1), array(f8, 1), array(f8, 1))  # fmt: skip


def assembled(ptxas: str, ptx: str, cc: tuple[int, int]) -> str:
    """``ptxas -v``'s report of the kernel's resources (registers, stack frame, spills) for ``sm_<cc>``."""
    with tempfile.TemporaryDirectory() as tmp:
        src = f"{tmp}/kernel.ptx"
        with open(src, "w", encoding="ascii") as f:
            f.write(ptx)
        proc = subprocess.run(
            [ptxas, "-v", f"-arch=sm_{cc[0]}{cc[1]}", src, "-o", f"{tmp}/kernel.cubin"],
            capture_output=True, text=True,
        )  # fmt: skip
    if proc.returncode != 0:
        raise SystemExit(f"ptxas failed: {proc.stderr.strip()[:2000]}")
    lines = proc.stderr.splitlines()
    entry = next(i for i, ln in enumerate(lines) if "Compiling entry function" in ln)
    frame = next(ln.strip() for ln in lines[entry:] if "stack frame" in ln)
    used = next(ln.split(": ", 1)[1] for ln in lines[entry:] if "Used " in ln)
    return f"{used}; {frame}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="*", default=["pendulum", "impact_oscillator", "bouncing_ball"])
    parser.add_argument("--cc", default="9.0", help="compute capability (default 9.0)")
    parser.add_argument("--tol", type=float, default=1e-10, help="the tolerance, for the Taylor order")
    parser.add_argument("--ptxas", help="ptxas to assemble the PTX with (its -v report: registers, spills)")
    parser.add_argument("--zdm", action="store_true", help="also the kernels with the discontinuity map")
    args = parser.parse_args()
    from numba import cuda

    cc = tuple(int(v) for v in args.cc.split("."))
    try:
        cuda.get_current_device()
    except Exception:  # (no device: its compute capability is --cc)
        import numba.cuda.dispatcher as dispatcher

        dispatcher.get_current_device = lambda: pytypes.SimpleNamespace(compute_capability=cc)
    for name in args.models:
        model = getattr(grazing.models, name)()
        variants = [
            (lyapunov, zdm_stop)
            for zdm_stop in ((-1, 0) if args.zdm else (-1,))
            for lyapunov in (False, True)
        ]
        for lyapunov, zdm_stop in variants:
            dm = model_functions(model._def, taylor_order(args.tol))
            kernel = build_kernel(dm, keep_rows(100), lyapunov, zdm_stop)
            start = time.perf_counter()
            ptx, _ = cuda.compile_ptx(kernel.py_func, kernel_signature(), cc=cc)
            seconds = time.perf_counter() - start
            # (the local frames of the kernel and the device functions not inlined, in bytes)
            local = [int(v) for v in re.findall(r"__local_depot\d+\[(\d+)\]", ptx)]
            print(
                f"{name}{' (Lyapunov)' if lyapunov else ''}{' (map)' if zdm_stop >= 0 else ''}: PTX for "
                f"sm_{cc[0]}{cc[1]}, {len(ptx)} "
                f"characters, local frames {local} bytes, {seconds:.1f} s"
            )
            if args.ptxas:
                print("   ", assembled(args.ptxas, ptx, cc))


if __name__ == "__main__":
    main()
