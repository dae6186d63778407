"""The git_commit provenance attribute is the commit of the package's own source tree: a copy
installed inside another repository's work tree (a project's ignored .venv) records 'unknown',
never that project's commit."""
from __future__ import annotations

import importlib.util
import shutil
import subprocess
from pathlib import Path

import pytest

import safebasins.core.provenance as provenance

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="needs git")


def git(cwd, *args):
    return subprocess.run(["git", "-C", str(cwd), *args], capture_output=True, text=True, check=True).stdout.strip()


def test_an_installed_copy_in_another_repository_records_unknown(tmp_path):
    project = tmp_path / "project"
    site = project / ".venv" / "lib" / "site-packages" / "safebasins" / "core"
    site.mkdir(parents=True)
    (project / ".gitignore").write_text(".venv/\n")
    git(project, "init", "-q")
    git(project, "add", ".gitignore")
    git(project, "-c", "user.name=u", "-c", "user.email=u@example.org", "commit", "-qm", "init")
    assert git(site, "rev-parse", "HEAD")  # git alone would name the project's commit
    shutil.copy(provenance.__file__, site / "provenance.py")
    spec = importlib.util.spec_from_file_location("copied_provenance", site / "provenance.py")
    copy = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(copy)
    assert copy.git_commit() == "unknown"


def test_the_checkout_records_its_head():
    src = Path(provenance.__file__).resolve().parent
    try:
        head = git(src, "rev-parse", "HEAD")
        git(src, "ls-files", "--error-unmatch", "provenance.py")
    except subprocess.CalledProcessError:
        pytest.skip("the package is not imported from a git checkout")
    assert provenance.git_commit() in (head, head + "-dirty")
