"""The damped commands run without a Python warning reaching the user (runtime and user warnings
turned into errors in the child), and the damped F_cr figure draws (it has no mechanism branches)."""
from __future__ import annotations

import os

import pytest

from tests.cli.test_cli import CHART, run

#: the categories the library and numpy warn with (a third party's DeprecationWarning is not ours)
STRICT = dict(os.environ, PYTHONWARNINGS="error::RuntimeWarning,error::UserWarning")


@pytest.mark.parametrize("args", [
    [*CHART, "--damping", "0.01"],
    ["basin", "--F", "0.02", "--Omega", "0.9", "--Psi", "pi", "--xi-max", "0.18", "--n", "12x10", "--damping", "0.05"],
    ["fcr", "--xi-max", "0.15", "--Omega-range", "0.8,1.0,3", "--damping", "0.01"],
    ["fcr", "--xi-max", "0.15,0.15", "--Omega-range", "0.8,1.0,3", "--damping", "0.01,0.02"],
    ["escape-probability", "--F", "0.05", "--Omega", "0.9", "--xi-max", "0.2", "--noise", "0.06", "--t-eval", "2",
     "--n", "5", "--paths", "8", "--damping", "0.05"],
], ids=["chart", "basin", "fcr", "fcr-two-betas", "escape-probability"])
def test_damped_commands_warn_nothing(tmp_path, args):
    res = run([*args, "-o", "x"], tmp_path, env=STRICT)
    assert res.returncode == 0, res.stderr
    assert "Warning" not in res.stderr and "Warning" not in res.stdout, res.stderr
    assert (tmp_path / "x.png").stat().st_size > 0
