"""Rule `parameters`: write one experiment's resolved parameters (results/params/{experiment}.yaml)."""
import json
import os
import tempfile
from pathlib import Path

from safebasins.config import dump_params, redirect_output

redirect_output(snakemake.log[0])
params = json.loads(snakemake.params.spec)
out = Path(snakemake.output[0])
text = (f"# Resolved parameters of {params['experiment']} ({params['kind']}), generated from the\n"
        "# configuration by the `parameters` rule; edit config/config.yaml, not this file.\n"
        + dump_params(params))
out.parent.mkdir(parents=True, exist_ok=True)
fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", dir=out.parent)
with os.fdopen(fd, "w") as fh:
    fh.write(text)
os.chmod(tmp, 0o644)
os.replace(tmp, out)
print(f"wrote {out}")
