"""Rule `archive`: results/archive/safebasins-results.tar.gz with every dataset, the resolved
parameter files, the validated configuration, environment.lock, the installed package versions
and a SHA-256 manifest (MANIFEST.sha256, `sha256sum -c` format)."""
import hashlib
import importlib.metadata as md
import io
import json
import os
import sys
import tarfile
import tempfile
import time
from pathlib import Path

import yaml

from safebasins import __version__
from safebasins.config import redirect_output
from safebasins.datasets import git_commit

redirect_output(snakemake.log[0])
PREFIX = "safebasins-results"
members = {}  # archive name -> bytes
for f in list(snakemake.input.datasets) + list(snakemake.input.params):
    name = str(Path(f).relative_to("results")) if f.startswith("results/") else f
    members[name] = Path(f).read_bytes()
members["environment.lock"] = Path(snakemake.input.lock).read_bytes()
members["config.resolved.yaml"] = yaml.safe_dump(json.loads(snakemake.params.config), sort_keys=False).encode()
dists = sorted({f"{d.metadata['Name']}=={d.version}" for d in md.distributions() if d.metadata["Name"]},
               key=str.lower)
members["environment.installed.txt"] = (f"# python {sys.version.split()[0]} on {sys.platform}\n"
                                        + "\n".join(dists) + "\n").encode()
members["PROVENANCE.json"] = json.dumps({"safebasins_version": __version__, "git_commit": git_commit(),
                                         "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())},
                                        indent=2).encode()
manifest = "".join(f"{hashlib.sha256(b).hexdigest()}  {n}\n" for n, b in sorted(members.items()))
members["MANIFEST.sha256"] = manifest.encode()

out = Path(snakemake.output[0])
out.parent.mkdir(parents=True, exist_ok=True)
fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", dir=out.parent)
os.close(fd)
now = int(time.time())
with tarfile.open(tmp, "w:gz") as tar:
    for name in sorted(members):
        data = members[name]
        info = tarfile.TarInfo(f"{PREFIX}/{name}")
        info.size, info.mtime, info.mode = len(data), now, 0o644
        tar.addfile(info, io.BytesIO(data))
os.chmod(tmp, 0o644)
os.replace(tmp, out)
print(f"wrote {out}: {len(members)} members")
print(manifest)
