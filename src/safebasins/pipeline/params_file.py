"""Rule ``parameters``: one experiment's resolved parameters as YAML
(results/params/{experiment}.yaml).  Kept apart from the rule-script runtime, which loads
numba and the kinds: this job runs once per experiment and needs neither."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import yaml

from safebasins.io.files import atomic_path
from safebasins.io.params import params_hash


def dump_params(params: dict[str, Any]) -> str:
    return yaml.safe_dump(params, sort_keys=False, default_flow_style=None, width=100)


def write_params(smk: Any) -> None:
    """Write one experiment's resolved parameters (``smk.params.spec``, JSON) atomically."""
    params = json.loads(smk.params.spec)
    path = Path(smk.output[0])
    text = (f"# Resolved parameters of {params['experiment']} ({params['kind']}), generated from the\n"
            "# configuration by the `parameters` rule; edit config/config.yaml, not this file.\n"
            + dump_params(params))
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    Path(smk.log[0]).parent.mkdir(parents=True, exist_ok=True)
    Path(smk.log[0]).write_text(f"wrote {path} (params sha256 {params_hash(params)})\n")
