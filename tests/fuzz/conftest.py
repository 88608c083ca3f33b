"""The fuzz's workspace template, made once per test process."""

from __future__ import annotations

import pytest

from tests.fuzz.check import Template, make_template


@pytest.fixture(scope="session")
def template(tmp_path_factory) -> Template:
    """The folder of a user's files, grazing's files and model files every case runs in a copy of."""
    return make_template(tmp_path_factory.mktemp("fuzz-template"))
