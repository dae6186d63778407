"""The ``damping`` key of every experiment block: validated (finite, >= 0), refused by
kinds written for the undamped equation (naming the key), recorded in the parameters only when
beta > 0 (the undamped run's parameter files and datasets stay as they were)."""
from __future__ import annotations

import pytest

from safebasins.pipeline.config import ConfigError
from safebasins.pipeline.plan import plan
from safebasins.pipeline.registry import KINDS
from tests.pipeline.test_config import base, merged  # noqa: F401  (the fixture)


def refused(cfg, key):
    with pytest.raises(ConfigError) as exc:
        plan(cfg)
    assert str(exc.value).startswith(f"config key {key}: "), str(exc.value)
    return str(exc.value)


def test_every_kind_has_the_damping_key_with_default_zero(base):
    run = plan(base)
    for name, exp in run.experiments.items():
        if exp.key.startswith("damped."):
            beta = exp.params["damping"]
            assert min(beta if isinstance(beta, list) else [beta]) > 0
        else:
            assert "damping" not in exp.params, name          # beta = 0: no parameter, files unchanged


@pytest.mark.parametrize("value, why", [(-0.1, "minimum"), (float("nan"), "finite"), (float("inf"), "finite"),
                                        ("0.1", "number")])
def test_bad_damping_is_named(base, value, why):
    msg = refused(merged(base, {"escape_equation": {"basins_xi": {"damping": value}}}),
                  "escape_equation.basins_xi.damping")
    assert why in msg or "is not of type" in msg or "less than the minimum" in msg, msg


def test_kinds_without_damping_refuse_it(base):
    undamped = sorted(n for n, k in KINDS.items() if not k.damped)
    assert "strobe" in undamped and "true_basin" in undamped and "tangency" not in undamped
    msg = refused(merged(base, {"figures": {"fig18": {"damping": 0.05}}}), "figures.fig18.damping")
    assert "'strobe' is written for the undamped equation" in msg
    plan(merged(base, {"figures": {"fig18": {"damping": 0.0}}}))      # 0 is the undamped equation


def test_tangency_needs_damping_and_its_basins_among_F(base):
    refused(merged(base, {"damped": {"escape_equation": {"damping": 0.0}}}), "damped.escape_equation.damping")
    msg = refused(merged(base, {"damped": {"escape_equation": {"basins_F": [0.0551]}}}),
                  "damped.escape_equation.basins_F[0]")
    assert "is not one of the F values" in msg


def test_damped_chart_tiles_integrate_the_damped_equation(base):
    """A damped experiment's chart tasks carry beta to the engine (one tile = one escape_chart)."""
    import numpy as np

    from safebasins.numerics import escape_chart
    from safebasins.pipeline.registry import Job
    from safebasins.pipeline.registry import chart_tile
    from safebasins.pipeline.values import base_well, grid_axes

    cfg = merged(base, {"damped": {"escape_equation": {"grid": {"n": 9}, "cycles": 40, "t_eval": [20, 40]}}})
    exp = plan(cfg).experiments["damped_tangency"]
    p = exp.params
    tile = chart_tile(exp.kind, p, 3, 0, 1, Job())
    q0, p0 = grid_axes(p["grid"])
    ref = escape_chart(q0, p0, p["tasks"][3]["F"], p["Omega"], p["Psi"], xi_max=(p["xi_max"],), cycles=40,
                       well=base_well(p), damping=0.1)
    assert tile.attrs["damping"] == 0.1
    np.testing.assert_array_equal(tile["escape_cycle_energy"].values, ref["escape_cycle_energy"].values)


def test_fcr_damping_list_makes_one_curve_per_beta(base):
    run = plan(base)
    p = run.experiments["damped_quartic_fcr"].params
    assert [c["damping"] for c in p["curves"]] == p["damping"] == [0.005, 0.01, 0.02]
    assert [c["label"] for c in p["curves"]] == ["damping = 0.005", "damping = 0.01", "damping = 0.02"]
    msg = refused(merged(base, {"damped": {"quartic_fcr": {"damping": [0.0, 0.01]}}}), "damped.quartic_fcr.damping")
    assert "every value must be > 0" in msg
    refused(merged(base, {"damped": {"quartic_fcr": {"damping": [0.01, 0.02], "xi_max": [0.1, 0.12, 0.15]}}}),
            "damped.quartic_fcr.damping")                          # 2 values against 3 curves


def test_damped_analytic_fcr_curves_are_the_theory_per_curve():
    """analysis.fcr_curves stacks theory.critical_forcing(..., damping=beta) per curve, with the
    coordinate damping; undamped curves keep their old coordinates."""
    import numpy as np

    from safebasins.analysis.fcr_curves import analytic_fcr_curves
    from safebasins.theory import critical_forcing

    Om = np.array([0.9, 0.95])
    curves = [{"label": f"damping = {b}", "xi_max": 0.15, "xi_ini": 0.0, "gamma_ini": 0.0, "damping": b}
              for b in (0.01, 0.02)]
    out = analytic_fcr_curves(Om, curves)
    assert out["damping"].values.tolist() == [0.01, 0.02]
    for i, b in enumerate((0.01, 0.02)):
        ref = critical_forcing(Om, 0.15, damping=b)
        np.testing.assert_array_equal(out["F_cr"].isel(curve=i).values, ref["F_cr"].values)
    und = analytic_fcr_curves(Om, [{k: v for k, v in curves[0].items() if k != "damping"}])
    assert "damping" not in und.coords and "mechanism" in und
