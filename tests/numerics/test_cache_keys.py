"""A kernel cached on disk is never reused after an edit of a module inlined into it.

numba's disk cache checks only the source file of the cached function itself.  The engine's
kernels inline the schemes' generated steps, the period loops, the steps and the wells' compiled
form; every cached kernel is specialised on a scheme key (numba literal), which hashes every file
the kernels import (scheme_code.ENGINE_FILES), so an edit of any of them is a new key and a new
compilation (measured: a comment added to periods.py recompiles _run_task, NUMBA_DEBUG_CACHE=1).
"""
from __future__ import annotations

import inspect
import shutil
from pathlib import Path

from numba.core.caching import NullCache
from numba.core.registry import CPUDispatcher

from safebasins.core import numba_target
from safebasins.numerics import kernels, periods, scheme_code, schemes, steps, well_loops
from safebasins.wells import compiled
from tests.import_graph import closure, graph, module_name

ENGINE_MODULES = (kernels, periods, scheme_code, schemes, steps, well_loops, compiled, numba_target)
#: cached dispatchers that inline nothing from another file (keyed by their own file alone)
SELF_CONTAINED = {"safebasins.wells.compiled._fma_python", "safebasins.numerics.steps.wtuple"}


def test_engine_files_are_what_the_kernels_import():
    want = {"safebasins.numerics.kernels"} | closure(graph(), "safebasins.numerics.kernels")
    assert {module_name(p) for p in scheme_code.ENGINE_FILES} | {"safebasins.numerics.kernels"} == want
    assert {m.__name__ for m in ENGINE_MODULES} == want


def test_every_cached_kernel_is_specialised_on_the_scheme_key():
    """A disk-cached dispatcher of the engine takes the scheme key, or inlines nothing from
    another file (inline="always" functions are compiled into their callers, not cached alone)."""
    bad, cached = [], 0
    for mod in ENGINE_MODULES:
        for name, obj in vars(mod).items():
            if not isinstance(obj, CPUDispatcher) or obj.py_func.__module__ != mod.__name__:
                continue
            if isinstance(obj._cache, NullCache) or obj.targetoptions.get("inline") == "always":
                continue
            cached += 1
            full = f"{mod.__name__}.{name}"
            if "scheme" not in inspect.signature(obj.py_func).parameters and full not in SELF_CONTAINED:
                bad.append(full)
    assert bad == [] and cached >= 6        # _run_task, the well_loops pointer targets, _final_states, _fma_python


def test_an_edit_of_any_engine_file_is_a_new_fingerprint(tmp_path):
    copies = []
    for k, path in enumerate(scheme_code.ENGINE_FILES):
        copies.append(tmp_path / f"{k}_{Path(path).name}")
        shutil.copy(path, copies[-1])
    base = scheme_code.fingerprint(copies)
    assert base == scheme_code.engine_fingerprint()
    for c in copies:
        text = c.read_bytes()
        c.write_bytes(text + b"# a comment\n")
        assert scheme_code.fingerprint(copies) != base, c.name
        c.write_bytes(text)


def test_a_well_key_hashes_its_source_and_the_compiled_form_module():
    code = compiled.polynomial_code([0.0, 0.0, 0.5, -0.25], (-1.0, 1.0))
    again = compiled.polynomial_code([0.0, 0.0, 0.5, -0.25], (-1.0, 1.0))
    other = compiled.WellCode("x", code.make, code.wpar, False, code.source + "\n# edited")
    assert again.key == code.key != other.key
    assert compiled.MODULE_HASH == scheme_code.fingerprint([compiled.__file__])
