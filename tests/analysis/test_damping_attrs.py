"""Every public analysis function that takes damping records it: a dataset made with beta > 0
carries the attribute ``damping`` (as numerics.engine.damping_attrs writes it), an undamped one
none; the numeric check of a damped basin integrates the damped equation."""
import numpy as np
import pytest

from safebasins.analysis import erosion, fractality, ic_basins, integrity_map, phase_invariant
from safebasins.numerics import escape_chart

Q = np.linspace(-0.8, 0.8, 9)
P = np.linspace(-0.6, 0.6, 7)
BETA = 0.05


def _made(beta):
    """name -> Dataset of each public function, made with damping ``beta`` (tiny grids, short runs)."""
    kw = {"damping": beta}
    chart = dict(cycles=10, steps_per_cycle=8, **kw)
    basin = ic_basins.analytic_basin(0.03, 0.85, np.pi, 0.18, Q, P, **kw)
    charts = [escape_chart(Q, P, f, 0.85, np.pi, xi_max=(0.18,), cycles=10, steps_per_cycle=8, **kw).assign_attrs(F=f)
              for f in (0.0, 0.03)]
    return {
        "erosion_profile_analytic": erosion.erosion_profile_analytic([0.0, 0.03], 0.85, np.pi, 0.18, Q, P, **kw),
        "erosion_profile_numeric": erosion.erosion_profile_numeric([0.0, 0.03], 0.85, np.pi, 0.18, Q, P, **chart),
        "profile_from_charts": erosion.profile_from_charts(charts),
        "true_safe_basin_numeric": phase_invariant.true_safe_basin_numeric(0.03, 0.85, 0.18, Q, P,
                                                                           Psi_values=[0.0, np.pi], **chart),
        "integrity_map_numeric": integrity_map.integrity_map_numeric([0.85], [0.0, 0.03], np.pi, 0.18, Q, P, **chart),
        "uncertainty_exponent": fractality.uncertainty_exponent(0.03, 0.85, np.pi, 0.18, ((-0.5, 0.5), (-0.4, 0.4)),
                                                                n=100, **chart),
        "analytic_basin": basin,
        "analytic_basin_stack": ic_basins.analytic_basin_stack("F", [0.02, 0.03], 0.03, 0.85, np.pi, 0.18, Q, P, **kw),
        "numeric_check": ic_basins.numeric_check(basin, 0.03, 0.85, np.pi, 0.18, cycles=10, steps_per_cycle=8),
    }


@pytest.mark.parametrize("beta", [BETA, 0.0])
def test_every_dataset_records_its_damping(beta):
    made = _made(beta)
    for name, ds in made.items():
        if beta > 0:
            assert ds.attrs.get("damping") == beta, name
        else:
            assert "damping" not in ds.attrs, name          # the undamped equation's datasets are the paper's


def test_numeric_check_of_a_damped_basin_integrates_the_damped_equation():
    basin = ic_basins.analytic_basin(0.03, 0.85, np.pi, 0.18, Q, P, damping=BETA)
    chk = ic_basins.numeric_check(basin, 0.03, 0.85, np.pi, 0.18, cycles=30, steps_per_cycle=8)
    safe = ~basin["escapes"].values
    assert safe.any()
    QQ, PP = np.meshgrid(Q, P, indexing="ij")
    ref = escape_chart(QQ[safe], PP[safe], 0.03, 0.85, np.pi, xi_max=(0.18,), cycles=30, steps_per_cycle=8,
                       grid=False, damping=BETA)["escape_cycle_energy"].isel(xi_max=0).values
    np.testing.assert_array_equal(chk["escape_cycle_numeric"].values[safe], ref)
