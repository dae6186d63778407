"""The part of environment.lock that a wheel's declared dependencies need, hashes kept.

    python .ci/lock_subset.py dist/safebasins-0.1.0-py3-none-any.whl [EXTRA ...] < environment.lock

Prints the lock entries (pin and hashes) of the wheel's Requires-Dist for the given extras and,
transitively, of what those declare, read from the metadata of the environment this runs in
(installed from the same lock, so the same versions).  A fresh venv installed from the output
with ``pip install --require-hashes --no-deps`` then holds only what the metadata declares: an
undeclared import fails there, and ``pip check`` proves the declaration complete.  A needed
package missing from the lock is an error.
"""
from __future__ import annotations

import re
import sys
import zipfile
from email.parser import Parser
from importlib import metadata

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name


def wheel_requires(path: str) -> tuple[str, list[str]]:
    """(project name, Requires-Dist lines) of a wheel's METADATA."""
    with zipfile.ZipFile(path) as zf:
        name = next(n for n in zf.namelist() if n.endswith(".dist-info/METADATA"))
        meta = Parser().parsestr(zf.read(name).decode())
    return meta["Name"], meta.get_all("Requires-Dist") or []


def closure(project: str, requires: list[str], extras: list[str]) -> set[str]:
    """Canonical names of every distribution the requirements need (markers evaluated for the
    requested extras; the project's own extras expanded in place)."""
    need: set[str] = set()
    todo = [(project, requires, set(extras))]
    seen: set[tuple[str, frozenset]] = set()
    while todo:
        owner, reqs, wanted = todo.pop()
        key = (owner, frozenset(wanted))
        if key in seen:
            continue
        seen.add(key)
        for line in reqs:
            req = Requirement(line)
            if req.marker is not None and not any(req.marker.evaluate({"extra": e}) for e in ("", *wanted)):
                continue
            name = canonicalize_name(req.name)
            if name == canonicalize_name(project):
                todo.append((project, requires, set(req.extras)))
                continue
            need.add(name)
            todo.append((name, metadata.distribution(name).requires or [], set(req.extras)))
    return need


def lock_entries(text: str) -> dict[str, str]:
    """Canonical name -> the lock's entry (the pin line with its hashes and comments)."""
    entries, name = {}, None
    for line in text.splitlines(keepends=True):
        m = re.match(r"^([A-Za-z0-9][A-Za-z0-9._-]*)==", line)
        if m:
            name = canonicalize_name(m.group(1))
            entries[name] = line
        elif name is not None and line.startswith(" "):
            entries[name] += line
        else:
            name = None
    return entries


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__, file=sys.stderr)
        return 2
    project, requires = wheel_requires(argv[0])
    need = closure(project, requires, argv[1:])
    entries = lock_entries(sys.stdin.read())
    missing = sorted(need - set(entries))
    if missing:
        print(f"lock_subset.py: not in environment.lock: {', '.join(missing)} (run make lock)", file=sys.stderr)
        return 1
    sys.stdout.write("".join(entries[n] for n in sorted(need)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
