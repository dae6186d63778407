"""One rule for a threshold at the barrier energy: the well's checks, and the API, the config and the
command line that use them, agree."""
import copy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from safebasins import theory, wells
from safebasins.numerics import escape_chart
from safebasins.pipeline.config import ConfigError, REPO_ROOT, load_yaml, validate_config

SCRIPT = Path(sys.executable).with_name("safebasins")


@pytest.mark.parametrize("spec", [None, "cubic", "pendulum", {"expression": "q**2/2 - 0.05/(1-q) + 0.05 + 0.05*q"}])
def test_barrier_wells(spec):
    w = wells.resolve_well(spec)
    Eb = w.barrier_energy
    assert w.check_threshold("xi_max", Eb) == Eb                       # escape over the barrier
    with pytest.raises(ValueError, match="xi_max"):
        w.check_threshold("xi_max", Eb * (1 + 1e-9))
    for x in (Eb, Eb * (1 - 1e-13)):                                   # at it, or within 1e-12: the separatrix
        with pytest.raises(ValueError, match="xi_max must lie below the barrier energy"):
            w.check_analytic_threshold("xi_max", x)
    assert w.check_analytic_threshold("xi_max", Eb * (1 - 1e-9)) == Eb * (1 - 1e-9)


def test_open_well_refuses_its_limit_everywhere():
    w = wells.resolve_well("sech2")
    for check in (w.check_threshold, w.check_analytic_threshold):
        with pytest.raises(ValueError, match="unbounded"):
            check("xi_max", 1.0)


@pytest.mark.parametrize("spec", [None, "cubic"])
def test_api_undamped_theory_refuses_the_barrier_energy_damped_and_numerics_take_it(spec):
    """The undamped theory at xi_max = E_b raised a misleading 'E must be < ...' (cubic) or returned
    NaN without a word (quartic); now a ValueError naming xi_max.  The damped slow flow and the
    numerics test escape over the barrier there."""
    w = wells.resolve_well(spec)
    Eb = w.barrier_energy
    for call in (lambda: theory.critical_forcing(np.array([0.9]), Eb, well=spec),
                 lambda: theory.slow_flow_escapes(np.array([0.1]), np.array([0.0]), 0.01, 0.9, np.pi, Eb, well=spec),
                 lambda: theory.escapes_on_manifold(np.array([0.1]), np.array([0.05]), 0.01, 0.9, Eb, well=spec)):
        with pytest.raises(ValueError, match="xi_max must lie below the barrier energy"):
            call()
    esc = theory.slow_flow_escapes(np.array([0.0, 0.1]), np.array([0.0, 0.0]), 0.01, 0.9, np.pi, Eb, well=spec,
                                   damping=0.05)
    assert esc.shape == (2,)
    c = escape_chart([0.0, 0.1], [0.0], 0.05, 0.9, np.pi, xi_max=Eb, cycles=5, well=spec)
    assert c["escape_cycle_energy"].shape[-2:] == (2, 1)


def _config(experiments):
    cfg = load_yaml(REPO_ROOT / "config" / "config.yaml")
    cfg = copy.deepcopy(cfg)
    cfg["experiments"] = experiments
    return cfg


def _accepted_by_config(kind_block):
    try:
        validate_config(_config({"mine": kind_block}))
        return True
    except ConfigError as exc:
        assert "experiments.mine.xi_max" in str(exc), str(exc)
        return False


def _accepted_by_cli(args, tmp_path):
    res = subprocess.run([str(SCRIPT), *args, "--no-plot", "-q", "-o", str(tmp_path / "run")], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    if res.returncode == 2:
        assert "'--xi-max'" in res.stderr, res.stderr
        return False
    assert res.returncode == 0, res.stderr
    return True


@pytest.mark.parametrize("xi_max,damping", [(0.25, 0.0), (0.25 * (1 - 1e-13), 0.0), (0.25, 0.02), (0.2, 0.0)])
def test_api_config_and_command_line_agree(xi_max, damping, tmp_path):
    """An analytic basin chart (numerics + slow flow) at a threshold at, near or below E_b = 1/4."""
    try:
        theory.slow_flow_escapes(np.array([0.1]), np.array([0.0]), 0.01, 0.9, np.pi, xi_max, damping=damping)
        api = True
    except ValueError as exc:
        assert "xi_max" in str(exc)
        api = False
    block = {"kind": "basin_chart", "F": 0.01, "Omega": 0.9, "Psi": 3.14159, "xi_max": [xi_max], "cycles": 3,
             "grid": {"q0": [-0.9, 0.9], "p0": [-0.7, 0.7], "n": 4}, "damping": damping}
    config = _accepted_by_config(block)
    cli = _accepted_by_cli(["chart", "--F", "0.01", "--Omega", "0.9", "--Psi", "pi", "--xi-max", repr(xi_max),
                            "--n", "4", "--cycles", "3", "--damping", repr(damping)], tmp_path)
    assert api == config == cli == (damping > 0 or xi_max < 0.25 * (1 - 1e-12))
