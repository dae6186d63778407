"""The quick run every pipeline test module shares (tests/pipeline/quick_run.py)."""
from __future__ import annotations

import pytest

from tests.pipeline.quick_run import build, shared_dir


@pytest.fixture(scope="session")
def quick(tmp_path_factory):
    """(sandbox, CompletedProcess) of ``snakemake -j2 --keep-going all`` on the quick config."""
    shared = shared_dir(tmp_path_factory.getbasetemp())
    return shared / "quick", build(shared)
