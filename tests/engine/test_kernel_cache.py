"""The on-disk cache of a model's compiled functions."""

from __future__ import annotations

import numpy as np

from grazing.engine import codegen
from grazing.models import bouncing_ball


def test_a_damaged_cache_file_is_compiled_again(tmp_path, monkeypatch):
    monkeypatch.setenv("GRAZING_CACHE_DIR", str(tmp_path))
    model = bouncing_ball()
    key = "test_damaged_cache_file"
    path = tmp_path / f"grazing_model_{key}.bin"
    path.write_bytes(b"not a header\n\x00\x01")
    kernels = codegen.load_compiled(key, lambda: codegen.generate_source(model._def.system, 0, 8))
    assert (kernels.NX, kernels.ORDER) == (model.n_states, 8)
    x = np.array([0.7, -0.2])
    assert kernels.guard(x, 0.3, model.param_vector, 0) == model.guard(x, 0.3)
    assert path.read_bytes().split(b"\n", 1)[0].startswith(b"{")  # rewritten


def test_model_functions_are_compiled_once_and_shared(tmp_path, monkeypatch):
    monkeypatch.setenv("GRAZING_CACHE_DIR", str(tmp_path))
    model = bouncing_ball()
    key = "test_shared_cache_file"
    calls = []

    def source():
        calls.append(1)
        return codegen.generate_source(model._def.system, 0, 8)

    first = codegen.load_compiled(key, source)
    assert codegen.load_compiled(key, source) is first and calls == [1]
    codegen._loaded.pop(key)  # a new process: loads the file, compiles nothing
    again = codegen.load_compiled(key, source)
    assert calls == [1] and again.table[1:5] == first.table[1:5]
