"""The on-disk cache of a model's compiled functions."""

from __future__ import annotations

import os

import numpy as np
import pytest

from grazing.engine import codegen
from grazing.errors import WriteError
from grazing.models import bouncing_ball
from tests.processes import with_full_disk


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


# --------------------------------------------------------------------------
# issue 26: files -- nothing half-written in the cache, its folder checked


def test_a_failed_compilation_leaves_nothing_in_the_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("GRAZING_CACHE_DIR", str(tmp_path))

    def broken():
        raise RuntimeError("the compiler failed")

    with pytest.raises(RuntimeError, match="the compiler failed"):
        codegen.load_compiled("test_failed_compilation", broken)
    with pytest.raises(RuntimeError):
        codegen._cached_file("x.bin", lambda: codegen.compile_model(broken(), "x"))
    assert list(tmp_path.iterdir()) == []


def test_a_full_disk_leaves_nothing_in_the_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("GRAZING_CACHE_DIR", str(tmp_path))
    model = bouncing_ball()
    source = codegen.generate_source(model._def.system, 0, 8)
    got = with_full_disk(codegen.load_compiled, "test_full_disk_cache", lambda: source, limit=1024)
    assert got is not None and got[0] == "WriteError", got
    name = tmp_path / "grazing_model_test_full_disk_cache.bin"
    assert got[1] == f"cannot write {name}: File too large; nothing was written"
    assert list(tmp_path.iterdir()) == []


def test_an_unusable_grazing_cache_dir_is_refused_in_one_line(tmp_path, monkeypatch):
    blocker = tmp_path / "a-file"
    blocker.write_text("mine")
    for value in (blocker, blocker / "sub"):
        monkeypatch.setenv("GRAZING_CACHE_DIR", str(value))
        with pytest.raises(WriteError, match=f"GRAZING_CACHE_DIR={value} cannot hold the compiled kernels"):
            codegen._cached_file("x.bin", lambda: b"x")
    # issue 43: a missing nested path is a typo more often than a wish: its parents are not made
    monkeypatch.setenv("GRAZING_CACHE_DIR", str(tmp_path / "new" / "cache"))
    with pytest.raises(WriteError, match=f"its folder '{tmp_path / 'new'}' does not exist"):
        codegen._cached_file("x.bin", lambda: b"x")
    assert blocker.read_text() == "mine" and sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]
    monkeypatch.setenv("GRAZING_CACHE_DIR", str(tmp_path / "cache"))  # missing, in a folder that is: made
    assert codegen._cached_file("x.bin", lambda: b"x").read_bytes() == b"x"


def test_an_unusable_default_folder_falls_back_with_one_note(tmp_path, monkeypatch, capsys):
    import tempfile

    monkeypatch.delenv("GRAZING_CACHE_DIR", raising=False)
    (tmp_path / "home-cache").write_text("not a folder")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "home-cache"))
    (tmp_path / "tmp").mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    monkeypatch.setattr(codegen, "_NOTED", set())
    path = codegen._cached_file("x.bin", lambda: b"x")
    assert path.parent == tmp_path / "tmp" / f"grazing-cache-{os.getuid()}" and path.read_bytes() == b"x"
    assert (path.parent.stat().st_mode & 0o777) == 0o700  # private: others cannot plant kernels
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"grazing: note: {tmp_path / 'home-cache' / 'grazing'}")
    assert "cannot hold the compiled kernels (Not a directory); they are cached in" in err
    codegen._cached_file("y.bin", lambda: b"y")
    assert capsys.readouterr().err == ""  # said once
