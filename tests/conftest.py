"""Shared fixtures: a sandbox view of the repository for the workflow tests; the shared quick
pipeline run started in the background once the tests that need it are collected."""
from __future__ import annotations

import os

import pytest

from tests.pipeline import quick_run
from tests.pipeline.sandbox import make_sandbox


@pytest.fixture
def sandbox(tmp_path):
    return make_sandbox(tmp_path / "wd")


def pytest_collection_finish(session):
    # every xdist worker collects every test; the run's lock lets only the first one build it
    if session.config.option.collectonly:
        return
    if any(quick_run.FIXTURE in getattr(item, "fixturenames", ()) for item in session.items):
        quick_run.start_in_background(quick_run.shared_dir(session.config._tmp_path_factory.getbasetemp()))


def pytest_unconfigure(config):
    # the controller (or the only process) ends a run no test waited for
    factory = getattr(config, "_tmp_path_factory", None)
    if factory is not None and not os.environ.get("PYTEST_XDIST_WORKER") and factory._basetemp is not None:
        quick_run.stop_background(quick_run.shared_dir(factory.getbasetemp()))
