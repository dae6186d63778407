"""Checking a results archive (:mod:`safebasins.io.archive`) file by file.

``sha256sum -c MANIFEST.sha256`` checks only the files the manifest lists: a file added to the
crate afterwards goes unnoticed.  :func:`check_archive` reads the tarball (or an extracted crate
directory) and reports, one line each:

* a file present but not listed in ``MANIFEST.sha256``, or not described in
  ``ro-crate-metadata.json`` (every file but the metadata itself is a data entity there);
* a file listed or described but absent;
* a file whose SHA-256 (or size) differs from the manifest's or the metadata's;
* anything that is not one root directory ``safebasins-results/`` with the manifest and the
  metadata in it, or is not a regular file.

:func:`verify_archive` raises an :class:`ArchiveError` listing them.  From the shell::

    python -m safebasins.io.verify results/archive/safebasins-results.tar.gz
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
import tarfile
from pathlib import Path
from typing import IO, Any, cast

from safebasins.io.archive import MANIFEST, METADATA

__all__ = ["ArchiveError", "check_archive", "verify_archive"]


class ArchiveError(ValueError):
    """A results archive whose files disagree with its manifest or metadata (the message lists each)."""


def _digest(fh: Any) -> tuple[str, int]:
    h, n = hashlib.sha256(), 0
    for block in iter(lambda: fh.read(1 << 20), b""):
        h.update(block)
        n += len(block)
    return h.hexdigest(), n


def _files(path: Path) -> tuple[dict[str, tuple[str, int]], dict[str, bytes], list[str]]:
    """(crate-relative name -> (sha256, size), the manifest and metadata bytes, problems)."""
    files, texts, problems = {}, {}, []
    if path.is_dir():
        for p in sorted(path.rglob("*")):
            name = p.relative_to(path).as_posix()
            if p.is_symlink() or not (p.is_file() or p.is_dir()):
                problems.append(f"{name}: not a regular file")
            elif p.is_file():
                with open(p, "rb") as fh:
                    files[name] = _digest(fh)
                if name in (MANIFEST, METADATA):
                    texts[name] = p.read_bytes()
        return files, texts, problems
    with tarfile.open(path) as tar:
        roots = {m.name.split("/", 1)[0] for m in tar.getmembers()}
        if len(roots) != 1:
            problems.append(f"the archive holds {len(roots)} top-level entries ({', '.join(sorted(roots))}), "
                            "not one crate directory")
        for m in tar.getmembers():
            if m.isdir():
                continue
            name = m.name.split("/", 1)[1] if "/" in m.name else m.name
            if not m.isfile():
                problems.append(f"{name}: not a regular file")
                continue
            member = cast(IO[bytes], tar.extractfile(m))      # (a regular file: never None)
            files[name] = _digest(member)
            if name in (MANIFEST, METADATA):
                texts[name] = cast(IO[bytes], tar.extractfile(m)).read()
    return files, texts, problems


def _manifest(text: bytes) -> dict[str, str]:
    out = {}
    for line in text.decode().splitlines():
        if line.strip():
            digest, _, name = line.partition("  ")
            out[name] = digest
    return out


def _described(text: bytes) -> dict[str, dict]:
    """The metadata's file entities (local ids, not URLs nor the root)."""
    graph = json.loads(text)["@graph"]
    out = {}
    for e in graph:
        types = e.get("@type", [])
        types = types if isinstance(types, list) else [types]
        if "File" in types and "://" not in e["@id"] and not e["@id"].startswith("#"):
            out[e["@id"]] = e
    return out


def check_archive(path: Any) -> list[str]:
    """The problems of the results archive ``path`` (a ``.tar.gz`` or an extracted crate
    directory), one line each; an empty list: every file is listed, described and intact."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"archive {os.fspath(path)} does not exist")
    files, texts, problems = _files(path)
    for name in (MANIFEST, METADATA):
        if name not in texts:
            problems.append(f"{name} is missing")
    listed = _manifest(texts[MANIFEST]) if MANIFEST in texts else {}
    described = _described(texts[METADATA]) if METADATA in texts else {}
    for name in sorted(files):
        sha, size = files[name]
        if MANIFEST in texts and name != MANIFEST and name not in listed:
            problems.append(f"{name}: present but not listed in {MANIFEST}")
        elif name in listed and listed[name] != sha:
            problems.append(f"{name}: SHA-256 differs from {MANIFEST} (changed after the archive was written)")
        if METADATA in texts and name != METADATA and name not in described:
            problems.append(f"{name}: present but not described in {METADATA}")
        elif name in described and described[name].get("sha256", sha) != sha:
            problems.append(f"{name}: SHA-256 differs from {METADATA}")
        elif name in described and int(described[name].get("contentSize", size)) != size:
            problems.append(f"{name}: size differs from {METADATA}")
    for name in sorted(set(listed) - set(files)):
        problems.append(f"{name}: listed in {MANIFEST} but absent")
    for name in sorted(set(described) - set(files) - {MANIFEST, METADATA}):   # those two: reported above
        problems.append(f"{name}: described in {METADATA} but absent")
    return problems


def verify_archive(path: Any) -> Path:
    """:func:`check_archive`, raising :class:`ArchiveError` (naming the archive and each
    problem) unless the archive is intact; returns ``path``."""
    problems = check_archive(path)
    if problems:
        raise ArchiveError(f"{os.fspath(path)}: {len(problems)} problem(s):\n  " + "\n  ".join(problems))
    return Path(path)


def main(argv: Any = None) -> int:
    """``python -m safebasins.io.verify ARCHIVE...``: 0 when every archive is intact, else 1."""
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: python -m safebasins.io.verify ARCHIVE [ARCHIVE...]  (a .tar.gz or a crate directory)")
        return 0 if argv else 2
    status = 0
    for a in argv:
        try:
            verify_archive(a)
            print(f"{a}: intact (every file listed in {MANIFEST}, described in {METADATA}, SHA-256 matching)")
        except (ArchiveError, OSError, tarfile.TarError) as exc:
            print(exc, file=sys.stderr)
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
