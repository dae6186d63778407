"""The results archive: a gzipped tarball holding one Workflow Run RO-Crate.

`write_archive` packs every dataset, the resolved parameter files, the validated configuration,
environment.lock, the installed package versions, PROVENANCE.json, CITATION.cff and the workflow
definition into one directory `safebasins-results/` with

* `ro-crate-metadata.json`: RO-Crate 1.1 metadata conforming to the Workflow Run Crate profile
  0.5 (https://w3id.org/ro/wfrun/workflow/0.5) and the profiles it builds on (Process Run Crate
  0.5, Workflow RO-Crate 1.0). Root dataset (name, description, MIT license, datePublished,
  citation of the reproduced paper); mainEntity the Snakefile (File + SoftwareSourceCode +
  ComputationalWorkflow, programmingLanguage Snakemake); one CreateAction for the run
  (instrument the workflow, object the configuration + its scalar settings + the parameter files,
  result the datasets); every file a data entity with encodingFormat, contentSize and sha256;
  each input/output slot a FormalParameter; the software versions as SoftwareApplication;
* `MANIFEST.sha256`: SHA-256 of every other file in the crate, ro-crate-metadata.json included
  (`sha256sum -c MANIFEST.sha256` inside `safebasins-results/`).

The crate is assembled in a temporary directory beside the output and the tarball is written
through `safebasins.io.files.atomic_path` (temporary file renamed over the target when
complete): an interrupted or killed job never leaves a half archive, and nothing temporary
survives an error (leftovers of a SIGKILLed write are removed by the next write).
"""
from __future__ import annotations

import hashlib
import importlib.metadata as md
import io
import json
import os
import shutil
import sys
import tarfile
import tempfile
import time
import warnings
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import xarray as xr
import yaml
from rocrate.model.contextentity import ContextEntity
from rocrate.rocrate import ROCrate

from safebasins.core.version import __version__
from safebasins.core.provenance import git_commit
from safebasins.io.files import atomic_path

__all__ = ["write_archive", "build_crate", "installed_distributions", "KEY_PACKAGES", "PROFILES"]

PREFIX = "safebasins-results"
METADATA = "ro-crate-metadata.json"
MANIFEST = "MANIFEST.sha256"

RO_CRATE_VERSION = "1.1"  # the version Workflow Run Crate 0.5 and Workflow RO-Crate 1.0 build on
PROFILES = {  # profile permalink -> (name, version); the root dataset conformsTo all three
    "https://w3id.org/ro/wfrun/process/0.5": ("Process Run Crate", "0.5"),
    "https://w3id.org/ro/wfrun/workflow/0.5": ("Workflow Run Crate", "0.5"),
    "https://w3id.org/workflowhub/workflow-ro-crate/1.0": ("Workflow RO-Crate", "1.0"),
}
# schema.org terms used here that the RO-Crate 1.1 context predates (RO-Crate 1.1 appendix
# "Extending RO-Crate": extra terms go into an additional @context object).
EXTRA_TERMS = {"sha256": "http://schema.org/sha256"}

BIOSCHEMAS_WORKFLOW = "https://bioschemas.org/profiles/ComputationalWorkflow/1.0-RELEASE"
NETCDF_MIME = "application/x-netcdf"
NETCDF4_FORMAT = "https://docs.unidata.ucar.edu/netcdf-c/current/file_format_specifications.html"
YAML_MIME = "application/yaml"
SPDX = "https://spdx.org/licenses/"

# Distributions recorded as SoftwareApplication entities (environment.installed.txt lists all).
KEY_PACKAGES = ("snakemake", "numpy", "scipy", "numba", "xarray", "netCDF4", "matplotlib",
                "PyYAML", "rocrate")


def sha256_file(path: str | os.PathLike) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def installed_distributions() -> str:
    """`environment.installed.txt`: the Python version and every installed distribution."""
    dists = sorted({f"{d.metadata['Name']}=={d.version}" for d in md.distributions() if d.metadata["Name"]},
                   key=str.lower)
    return f"# python {sys.version.split()[0]} on {sys.platform}\n" + "\n".join(dists) + "\n"


def _now() -> str:
    return time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())


def _arcname(path: Path, base: Path, what: str) -> str:
    try:
        return Path(os.path.abspath(path)).relative_to(os.path.abspath(base)).as_posix()
    except ValueError:
        raise ValueError(f"{what} {path} is not under {base}") from None


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "._-" else "-" for c in name)


def _dataset_attrs(path: Path) -> dict:
    with xr.open_dataset(path) as ds:
        attrs = dict(ds.attrs)
    if not str(attrs.get("title", "")).strip():
        raise ValueError(f"dataset {path} has no global 'title' attribute")
    return attrs


def _config_values(config: Mapping) -> dict[str, object]:
    """The configuration's scalar settings (top level, and plain tables of scalars such as
    `numerics`) as 'a.b' -> value; the per-figure blocks are described by the parameter files."""
    scalar = (str, int, float, bool)
    out: dict[str, object] = {}
    for key, value in config.items():
        if isinstance(value, scalar):
            out[str(key)] = value
        elif isinstance(value, Mapping) and value and all(isinstance(v, scalar) for v in value.values()):
            out.update({f"{key}.{k}": v for k, v in value.items()})
    return out


def _value_type(value: Any) -> str:
    if isinstance(value, bool):
        return "Boolean"
    if isinstance(value, int):
        return "Integer"
    if isinstance(value, float):
        return "Float"
    return "Text"


class _Builder:
    """Adds entities to one ROCrate (contextual entities, files with size + sha256, parameters)."""

    def __init__(self, crate: ROCrate) -> None:
        self.crate = crate

    def entity(self, id_: str, type_: Any, /, **props: Any) -> Any:
        return self.crate.add(ContextEntity(self.crate, id_, properties={"@type": type_, **props}))

    def file(self, source: Any, dest: str, *, name: str, description: str, encoding: Any, **props: Any) -> Any:
        """A File data entity; `source` is a path, or the file's content (str/bytes)."""
        src: io.BytesIO | str
        if isinstance(source, (bytes, str)):
            data = source.encode() if isinstance(source, str) else source
            size, digest, src = len(data), hashlib.sha256(data).hexdigest(), io.BytesIO(data)
        else:
            size, digest, src = Path(source).stat().st_size, sha256_file(source), str(source)
        props = {"name": name, "description": description, "encodingFormat": encoding,
                 "contentSize": str(size), "sha256": digest, **props}
        return self.crate.add_file(src, dest, properties=props)

    def parameter(self, identifier: str, name: str, additional_type: str, example: Any, description: str,
                  **props: Any) -> Any:
        """A FormalParameter (an input/output slot of the workflow) linked with its value `example`
        both ways (workExample / exampleOfWork), as the Workflow Run Crate profile asks."""
        fp = self.crate.add_formal_parameter(name, additional_type, identifier=identifier, description=description,
                                             valueRequired=True, properties=props)
        fp["workExample"] = example
        example["exampleOfWork"] = fp
        return fp


def _readme(cff: Mapping, datasets: Sequence[tuple[str, str]], inputs: Sequence[str]) -> str:
    ref = cff["preferred-citation"]
    authors = ", ".join(f"{a.get('given-names', '')} {a.get('family-names', a.get('name', ''))}".strip()
                        for a in ref["authors"])
    lines = [f"# safebasins {__version__} results", "",
             f"Datasets of one run of the safebasins Snakemake workflow, reproducing {authors}, "
             f"*{ref['title']}*.", "",
             f"This directory is a Workflow Run RO-Crate: `{METADATA}` (RO-Crate {RO_CRATE_VERSION}; "
             + ", ".join(f"{n} {v}" for n, v in PROFILES.values())
             + ") describes every file, the workflow, the run, the software versions and the paper.", "",
             f"- verify: `sha256sum -c {MANIFEST}` (in this directory)",
             "- read a dataset: `xarray.open_dataset(\"data/<kind>/<name>.nc\")`",
             "- cite: `CITATION.cff`; software versions: `environment.lock`, `environment.installed.txt`", "",
             "## Inputs", "", *[f"- `{name}`" for name in inputs], "",
             "## Datasets", "", *[f"- `{path}`: {title}" for path, title in datasets], ""]
    return "\n".join(lines)


def _software(b: _Builder, packages: Sequence[str]) -> list:
    """safebasins (version + git commit), Python and the key packages as SoftwareApplication."""
    commit = git_commit()
    b.entity("#safebasins-git-commit", "PropertyValue", name="git commit", propertyID="git commit", value=commit)
    apps = [b.entity("#safebasins", "SoftwareApplication", name="safebasins", softwareVersion=__version__,
                     description=("Analytic and numeric safe basins for forced escape from a truncated quartic "
                                  f"well; version {__version__}, git commit {commit}"),
                     identifier={"@id": "#safebasins-git-commit"}, license={"@id": f"{SPDX}MIT"}),
            b.entity("https://www.python.org/", "SoftwareApplication", name="Python", url="https://www.python.org/",
                     softwareVersion=".".join(map(str, sys.version_info[:3])))]
    for pkg in packages:
        dist = md.distribution(pkg)  # PackageNotFoundError when a key package is missing
        name, version = dist.metadata["Name"], dist.version
        apps.append(b.entity(f"https://pypi.org/project/{name}/{version}/", "SoftwareApplication", name=name,
                             url=f"https://pypi.org/project/{name}/", softwareVersion=version))
    return apps


def _paper(b: _Builder, cff: Mapping) -> Any:
    """The paper (CITATION.cff preferred-citation) as a ScholarlyArticle with Person authors."""
    ref = cff.get("preferred-citation") or {}
    if not ref.get("title") or not ref.get("authors"):
        raise ValueError("CITATION.cff has no preferred-citation with title and authors")
    authors: list[Any] = []
    orgs: dict[str, Any] = {}
    for i, a in enumerate(ref["authors"]):
        given, family = a.get("given-names"), a.get("family-names")
        props = {"name": " ".join(x for x in (given, family) if x) or a["name"]}
        if given:
            props["givenName"] = given
        if family:
            props["familyName"] = family
        if a.get("affiliation"):
            props["affiliation"] = orgs.setdefault(a["affiliation"], b.entity(
                f"#organization-{len(orgs) + 1}", "Organization", name=a["affiliation"]))
        authors.append(b.entity(a.get("orcid") or f"#author-{i + 1}", "Person", **props))
    props = {"name": ref["title"], "headline": ref["title"], "author": authors}
    if ref.get("year"):
        props["datePublished"] = str(ref["year"])
    if ref.get("journal"):
        props["isPartOf"] = b.entity("#journal", "Periodical", name=ref["journal"])
    if ref.get("doi"):
        props["identifier"] = f"https://doi.org/{ref['doi']}"
    return b.entity(f"https://doi.org/{ref['doi']}" if ref.get("doi") else "#paper", "ScholarlyArticle", **props)


def build_crate(crate_dir: Path, datasets: Sequence[Path], params: Sequence[Path], lock: Path, config: Mapping, *,
                results_dir: Path, workflow: Path, workflow_parts: Sequence[Path], citation: Path,
                packages: Sequence[str], start_time: str | None = None, end_time: str | None = None) -> None:
    """Write the crate (its files, ro-crate-metadata.json, MANIFEST.sha256) into `crate_dir`."""
    created = _now()
    cff = yaml.safe_load(citation.read_text())
    crate = ROCrate(version=RO_CRATE_VERSION)
    crate.metadata.extra_terms.update(EXTRA_TERMS)
    b = _Builder(crate)

    # --- the workflow (mainEntity) and the software it ran with
    src = workflow.parent
    wf = crate.add_workflow(str(workflow), workflow.name, main=True, lang="snakemake",
                            lang_version=md.version("snakemake"), properties={
                                "name": "safebasins Snakemake workflow", "version": __version__,
                                "conformsTo": {"@id": BIOSCHEMAS_WORKFLOW},
                                "description": ("Snakemake workflow computing every dataset behind the "
                                                "paper's figures, from the configuration to netCDF datasets"),
                                "encodingFormat": "text/plain", "contentSize": str(workflow.stat().st_size),
                                "sha256": sha256_file(workflow)})
    for part in workflow_parts:
        wf.append_to("hasPart", b.file(part, _arcname(part, src, "workflow file"), name=part.name,
                                       description="Snakemake rule file of the workflow", encoding="text/plain"))
    wf["softwareRequirements"] = _software(b, packages)

    # --- inputs: the configuration, its scalar settings, the resolved parameter files
    cfg = b.file(yaml.safe_dump(dict(config), sort_keys=False), "config.resolved.yaml",
                 name="Validated configuration", encoding=YAML_MIME,
                 description="The configuration the workflow ran with, after schema validation and defaults")
    wf.append_to("input", b.parameter("#param-config", "config", "File", cfg,
                                      "Workflow configuration (config/config.yaml plus --configfile overlays)",
                                      encodingFormat=YAML_MIME))
    objects = [cfg]
    for key, value in _config_values(config).items():
        pv = b.entity(f"#pv-config-{_slug(key)}", "PropertyValue", name=key, value=value)
        wf.append_to("input", b.parameter(f"#param-config-{_slug(key)}", key, _value_type(value), pv,
                                          f"Configuration setting '{key}'"))
        objects.append(pv)
    for p in params:
        dest = _arcname(p, results_dir, "parameter file")
        pf = b.file(p, dest, name=f"Resolved parameters of {p.stem}", encoding=YAML_MIME,
                    description=f"Every parameter of experiment {p.stem}, resolved from the configuration")
        wf.append_to("input", b.parameter(f"#param-{_slug(dest)}", dest, "File", pf,
                                          f"Resolved parameter file of experiment {p.stem}", encodingFormat=YAML_MIME))
        objects.append(pf)

    # --- outputs: the netCDF datasets
    b.entity(NETCDF4_FORMAT, "WebSite", name="netCDF-4 file format (HDF5-based)")
    results, created_times = [], []
    for d in datasets:
        attrs = _dataset_attrs(d)
        dest = _arcname(d, results_dir, "dataset")
        extra = {}
        if attrs.get("date_created"):
            extra["dateCreated"] = str(attrs["date_created"])
            created_times.append(extra["dateCreated"])
        f = b.file(d, dest, name=str(attrs["title"]), description=str(attrs.get("description") or attrs["title"]),
                   encoding=[NETCDF_MIME, {"@id": NETCDF4_FORMAT}], **extra)
        wf.append_to("output", b.parameter(f"#param-{_slug(dest)}", dest, "File", f, f"Dataset {dest}",
                                           encodingFormat=NETCDF_MIME))
        results.append(f)

    # --- environment, provenance, citation, manifest
    b.file(lock, "environment.lock", name="environment.lock", encoding="text/plain",
           description="Hashed, PyPI-only lock of the Python environment (pip install --require-hashes)")
    b.file(installed_distributions(), "environment.installed.txt", name="Installed Python distributions",
           description="Python version and every distribution installed when the archive was written",
           encoding="text/plain")
    b.file(json.dumps({"safebasins_version": __version__, "git_commit": git_commit(), "created": created},
                      indent=2) + "\n", "PROVENANCE.json", name="Provenance summary", encoding="application/json",
           description="safebasins version, git commit and archive creation time")
    b.file(_readme(cff, [(f.id, f["name"]) for f in results], [p.id for p in objects if p.type == "File"]),
           "README.md", name="README", encoding="text/markdown", about={"@id": "./"},
           description="What this archive holds and how to verify and read it")
    b.file(citation, "CITATION.cff", name="Citation metadata (Citation File Format 1.2.0)", encoding=YAML_MIME,
           description="How to cite safebasins and the paper it reproduces", about={"@id": "./"})
    crate.add_file(None, MANIFEST, properties={  # no source: written after the metadata, which it hashes
        "name": "SHA-256 manifest", "encodingFormat": "text/plain",
        "description": f"SHA-256 of every other file in the crate, {METADATA} included (sha256sum -c format)"})

    # --- the run, the paper, the license, the profiles, the root dataset
    run = {"name": f"Run of the safebasins workflow {__version__}",
           "description": "Snakemake run that computed the datasets from the configuration",
           "endTime": end_time or (max(created_times) if created_times else created),
           "actionStatus": "http://schema.org/CompletedActionStatus"}
    if start_time:
        run["startTime"] = start_time
    action = crate.add_action(wf, identifier="#run", object=objects, result=results, properties=run)
    paper = _paper(b, cff)
    lic = b.entity(f"{SPDX}{cff['license']}", "CreativeWork", name=f"{cff['license']} License",
                   identifier=cff["license"])
    for pid, (name, version) in PROFILES.items():
        b.entity(pid, "CreativeWork", name=name, version=version)
    crate.name = f"safebasins {__version__} results: safe basins of a forced truncated quartic well"
    crate.description = (
        "Datasets, parameters, configuration and software environment of one run of the safebasins workflow, "
        f"reproducing {', '.join(a['name'] for a in paper['author'])}, '{paper['name']}'.")
    root = crate.root_dataset
    root["license"] = lic
    root["datePublished"] = created
    root["version"] = __version__
    root["conformsTo"] = [{"@id": pid} for pid in PROFILES]
    root["citation"] = paper
    root["mentions"] = action

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=f"No source for {MANIFEST}")
        crate.write(crate_dir)
    _write_manifest(crate_dir)


def _write_manifest(crate_dir: Path) -> None:
    names = sorted(p.relative_to(crate_dir).as_posix() for p in crate_dir.rglob("*") if p.is_file())
    (crate_dir / MANIFEST).write_text("".join(f"{sha256_file(crate_dir / n)}  {n}\n" for n in names if n != MANIFEST))


def _write_tar(crate_dir: Path, tar_path: Path, prefix: str) -> None:
    now = int(time.time())
    with tarfile.open(tar_path, "w:gz") as tar:
        for p in sorted(crate_dir.rglob("*")):
            if p.is_file():
                info = tarfile.TarInfo(f"{prefix}/{p.relative_to(crate_dir).as_posix()}")
                info.size, info.mtime, info.mode = p.stat().st_size, now, 0o644
                with open(p, "rb") as fh:
                    tar.addfile(info, fh)


def stale_workdirs(out: Path) -> list[Path]:
    """Crate directories that killed earlier writes of `out` left behind."""
    return sorted(p for p in out.parent.glob(f".{out.name}.*.d") if p.is_dir())


def write_archive(out_path: str | os.PathLike, datasets: Iterable, params: Iterable, lock: str | os.PathLike,
                  config: Mapping, *, workflow: str | os.PathLike, citation: str | os.PathLike,
                  workflow_parts: Iterable = (), results_dir: str | os.PathLike = "results",
                  packages: Sequence[str] = KEY_PACKAGES, prefix: str = PREFIX,
                  start_time: str | None = None, end_time: str | None = None) -> Path:
    """Write the Workflow Run RO-Crate tarball `out_path` atomically and return its path.

    datasets / params: the netCDF datasets and resolved parameter files, all under `results_dir`
    (their crate paths are relative to it: data/analytic/fcr_fig01.nc, params/fig01.yaml).
    lock: environment.lock. config: the validated configuration (a mapping).
    workflow: the Snakefile; workflow_parts: further workflow files under its directory (the
    rule files), kept at their relative paths. citation: CITATION.cff (its preferred-citation is
    the cited paper, its license the crate's license). start_time / end_time: ISO 8601 times of
    the run (end_time defaults to the newest dataset `date_created`; start_time is omitted).
    The tarball holds one directory `prefix`/ (the crate root).
    """
    out = Path(out_path)
    out.parent.mkdir(parents=True, exist_ok=True)
    for old in stale_workdirs(out):  # one writer per target: leftovers are from killed writes
        shutil.rmtree(old, ignore_errors=True)
    work = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".d", dir=out.parent))
    try:
        crate_dir = work / prefix
        build_crate(crate_dir, [Path(d) for d in datasets], [Path(p) for p in params], Path(lock), config,
                    results_dir=Path(results_dir), workflow=Path(workflow),
                    workflow_parts=[Path(p) for p in workflow_parts], citation=Path(citation),
                    packages=packages, start_time=start_time, end_time=end_time)
        with atomic_path(out) as tmp:
            _write_tar(crate_dir, tmp, prefix)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return out
