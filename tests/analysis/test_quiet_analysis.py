"""Library calls made the way a user makes them print nothing and warn nothing: the basins, their
numeric check and the erosion profiles, undamped and damped (a progress line only for a named job,
``label=``)."""
import warnings

import numpy as np

from safebasins.analysis import erosion, ic_basins

Q = np.linspace(-0.9, 0.9, 11)
P = np.linspace(-0.7, 0.7, 9)


def test_basins_and_profiles_are_quiet(capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for beta in (0.0, 0.02):
            b = ic_basins.analytic_basin(0.02, 0.9, np.pi, 0.18, Q, P, damping=beta)
            ic_basins.numeric_check(b, 0.02, 0.9, np.pi, 0.18, cycles=10, steps_per_cycle=8)
            ic_basins.analytic_basin_stack("xi_max", [0.14, 0.18], 0.02, 0.9, np.pi, 0.18, Q, P, damping=beta)
            erosion.erosion_profile_analytic([0.0, 0.02], 0.9, np.pi, 0.18, Q, P, damping=beta)
            erosion.erosion_profile_numeric([0.0, 0.02], 0.9, np.pi, 0.18, Q, P, cycles=10, steps_per_cycle=8,
                                            damping=beta)
    out = capsys.readouterr()
    assert out.out == "" and out.err == "", out


def test_a_named_job_gets_its_progress_line(capsys):
    ic_basins.analytic_basin(0.02, 0.9, np.pi, 0.18, Q, P, label="my_job")
    assert capsys.readouterr().out == "my_job: basin F=0.02 Omega=0.9 Psi=3.141592653589793 xi_max=0.18\n"
