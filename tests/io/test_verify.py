"""Checking a results archive (safebasins.io.verify): an intact archive passes; a file added to
the crate but not listed in MANIFEST.sha256 nor described in ro-crate-metadata.json, a listed
file removed and a changed file are each reported by name."""
from __future__ import annotations

import io
import tarfile
from pathlib import Path

import pytest

from safebasins.io import archive as sa
from safebasins.io.verify import ArchiveError, check_archive, main, verify_archive
from tests.io.test_archive import _write


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("verify")
    out = tmp / "out" / "safebasins-results.tar.gz"
    _write(tmp, out)
    return out


def _rewrite(src: Path, dst: Path, *, add=None, drop=None, change=None) -> Path:
    """A copy of the tarball with one member added, dropped or changed."""
    with tarfile.open(src) as old, tarfile.open(dst, "w:gz") as new:
        for m in old.getmembers():
            name = m.name.split("/", 1)[1] if "/" in m.name else ""
            if name == drop:
                continue
            data = old.extractfile(m).read() if m.isfile() else None
            if name == change:
                data = data + b"\n# edited\n"
                m.size = len(data)
            new.addfile(m, io.BytesIO(data) if data is not None else None)
        if add:
            info = tarfile.TarInfo(f"{sa.PREFIX}/{add}")
            info.size = 5
            new.addfile(info, io.BytesIO(b"extra"))
    return dst


def test_intact_archive_passes(archive, tmp_path):
    assert check_archive(archive) == []
    assert verify_archive(archive) == archive
    with tarfile.open(archive) as tar:
        tar.extractall(tmp_path, filter="data")
    assert check_archive(tmp_path / sa.PREFIX) == []          # an extracted crate too
    assert main([str(archive)]) == 0


def test_extra_unlisted_file_reported(archive, tmp_path):
    bad = _rewrite(archive, tmp_path / "a.tar.gz", add="data/numeric/stray.nc")
    problems = check_archive(bad)
    assert problems == ["data/numeric/stray.nc: present but not listed in MANIFEST.sha256",
                        "data/numeric/stray.nc: present but not described in ro-crate-metadata.json"]
    with pytest.raises(ArchiveError, match=r"a.tar.gz: 2 problem\(s\):\n  data/numeric/stray.nc: present but not "):
        verify_archive(bad)
    assert main([str(bad)]) == 1


def test_extra_file_in_an_extracted_crate_reported(archive, tmp_path):
    with tarfile.open(archive) as tar:
        tar.extractall(tmp_path, filter="data")
    root = tmp_path / sa.PREFIX
    (root / "notes.txt").write_text("added later\n")
    assert "notes.txt: present but not listed in MANIFEST.sha256" in check_archive(root)


def test_missing_and_changed_files_reported(archive, tmp_path):
    gone = _rewrite(archive, tmp_path / "gone.tar.gz", drop="params/fig01.yaml")
    assert check_archive(gone) == ["params/fig01.yaml: listed in MANIFEST.sha256 but absent",
                                   "params/fig01.yaml: described in ro-crate-metadata.json but absent"]
    changed = _rewrite(archive, tmp_path / "changed.tar.gz", change="params/fig13.yaml")
    assert check_archive(changed) == ["params/fig13.yaml: SHA-256 differs from MANIFEST.sha256 (changed after the "
                                      "archive was written)", "params/fig13.yaml: SHA-256 differs from "
                                      "ro-crate-metadata.json"]
    no_manifest = _rewrite(archive, tmp_path / "nomanifest.tar.gz", drop=sa.MANIFEST)
    assert check_archive(no_manifest) == ["MANIFEST.sha256 is missing"]


def test_missing_archive_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="none.tar.gz"):
        check_archive(tmp_path / "none.tar.gz")
