"""Datasets the public API returns carry their provenance: version, commit, date, the
call's parameters and the well, as the pipeline's datasets do."""
from __future__ import annotations

import json

import numpy as np

from safebasins import __version__
from safebasins.core.provenance import PROVENANCE_ATTRS
from safebasins.core.stacking import stack
from safebasins.numerics import critical_forcing_numeric, escape_chart


def test_api_datasets_carry_provenance():
    q = np.linspace(-0.5, 0.5, 30)
    ch = escape_chart(q, q[:4], 0.01, 0.9, np.pi, xi_max=(0.1,), cycles=5, well={"polynomial": [0, 0, 0.5, -1 / 3]})
    a = ch.attrs
    assert a["safebasins_version"] == __version__ and a["git_commit"] and a["date_created"]
    assert a["history"].startswith("safebasins.numerics") and a["well"] == "polynomial"
    p = json.loads(a["parameters"])
    assert p["F"] == 0.01 and p["cycles"] == 5 and p["well"] == {"polynomial": [0, 0, 0.5, -1 / 3]}
    assert p["q0"] == {"shape": [30], "min": -0.5, "max": 0.5} and p["p0"] == q[:4].tolist()
    f = critical_forcing_numeric([0.9], 0.1, cycles=5, n_scan=0, tol=1e-2)
    assert f.attrs["well"] == "quartic" and json.loads(f.attrs["parameters"])["Omega"] == [0.9]


def test_stack_drops_the_parts_provenance():
    q = np.linspace(-0.5, 0.5, 5)
    parts = [escape_chart(q, q, F, 0.9, np.pi, xi_max=(0.1,), cycles=3) for F in (0.01, 0.02)]
    out = stack(parts, "F", [0.01, 0.02], pad=())
    assert not set(PROVENANCE_ATTRS) & set(out.coords) and not set(PROVENANCE_ATTRS) & set(out.attrs)


def _body(fn) -> str:
    """The source of a function's body: its docstring and statements, not its signature (a
    function that takes or is annotated as returning a Dataset it does not build is not caught)."""
    import ast
    import inspect
    import textwrap

    src = textwrap.dedent(inspect.getsource(fn))
    node = ast.parse(src).body[0]
    assert isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
    return "\n".join(ast.get_source_segment(src, stmt) or "" for stmt in node.body)


def test_every_public_function_returning_a_dataset_is_wrapped():
    """The public functions of theory, numerics and analysis whose result is a Dataset carry the
    provenance decorator (safebasins.wells.provenance.api_provenance): one list, checked against the modules."""
    import importlib
    import inspect

    modules = ["safebasins.theory", "safebasins.numerics", "safebasins.analysis.melnikov",
               "safebasins.analysis.erosion", "safebasins.analysis.phase_invariant", "safebasins.analysis.period_map",
               "safebasins.analysis.fourier_compare", "safebasins.analysis.ic_basins",
               "safebasins.analysis.fcr_curves", "safebasins.analysis.tangency", "safebasins.analysis.fractality",
               "safebasins.analysis.integrity_map"]
    missing = []
    for name in modules:
        mod = importlib.import_module(name)
        for fn_name in mod.__all__:
            fn = getattr(mod, fn_name)
            if inspect.isfunction(fn) and "xr.Dataset" in _body(inspect.unwrap(fn)) \
                    and not hasattr(fn, "__wrapped__"):
                missing.append(f"{name}.{fn_name}")
    assert missing == [], missing


def test_analysis_datasets_carry_provenance():
    from safebasins.analysis.melnikov import melnikov_curve

    ds = melnikov_curve([0.8, 0.9], 0.1, well="cubic")
    assert ds.attrs["safebasins_version"] == __version__ and ds.attrs["well"] == "cubic"
    assert json.loads(ds.attrs["parameters"])["damping"] == 0.1
