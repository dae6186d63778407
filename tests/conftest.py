"""Shared fixtures: a sandbox view of the repository for the workflow tests."""
from __future__ import annotations

import pytest

from tests.pipeline.sandbox import make_sandbox


@pytest.fixture
def sandbox(tmp_path):
    return make_sandbox(tmp_path / "wd")
