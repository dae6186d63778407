"""The results archive (safebasins.io.archive): a Workflow Run RO-Crate in a tarball.

A small synthetic results tree (three tiny netCDF datasets, two parameter files, a lock file,
a Snakefile stub with one rule file, the repository's CITATION.cff) is archived; the checks:
atomic write (nothing temporary left, an interrupted write leaves nothing), MANIFEST.sha256,
every file described and reachable from the root dataset, the netCDF entities, and validation
with roc-validator, offline, against the Workflow Run Crate profile (which runs the checks of
Process Run Crate 0.5, Workflow RO-Crate 1.0 and RO-Crate 1.1 too)."""
from __future__ import annotations

import hashlib
import io
import json
import tarfile
import tomllib
from pathlib import Path

import numpy as np
import pytest
import requests
import rocrate
import urllib3
import xarray as xr
import yaml

import safebasins
from safebasins.io import archive as sa

ROOT = Path(__file__).resolve().parents[2]
CONTEXT_URL = "https://w3id.org/ro/crate/1.1/context"
TITLES = {"data/analytic/fcr_fig01.nc": "Critical forcing F_cr(Omega), analytic",
          "data/numeric/chart_fig13.nc": "Safe basins versus xi_max, numeric",
          "data/extras/erosion_numeric.nc": "Erosion profiles (GIM, LIM, IF) versus F"}
CONFIG = {"fourier": "paper", "seed": 20230101,
          "numerics": {"steps_per_cycle": 32, "threads": 1, "tiles": 1},
          "figures": {"fig01": {"xi_max": 0.242, "Omega": {"start": 0.5, "stop": 1.2, "num": 5}}}}


def _tree(tmp_path: Path) -> dict:
    res, src = tmp_path / "results", tmp_path / "src"
    datasets = []
    for i, (name, title) in enumerate(TITLES.items()):
        path = res / name
        path.parent.mkdir(parents=True, exist_ok=True)
        xr.Dataset({"v": ("x", np.arange(4.0) + i)},
                   attrs={"title": title, "date_created": f"2026-01-0{i + 1}T00:00:00+00:00"}).to_netcdf(path)
        datasets.append(path)
    params = []
    for exp in ("fig01", "fig13"):
        path = res / "params" / f"{exp}.yaml"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(yaml.safe_dump({"experiment": exp, "F": 0.015}))
        params.append(path)
    (src / "workflow" / "rules").mkdir(parents=True)
    (src / "Snakefile").write_text('include: "workflow/rules/a.smk"\n')
    rule = src / "workflow" / "rules" / "a.smk"
    rule.write_text("rule a:\n    output: 'x'\n")
    (src / "CITATION.cff").write_bytes((ROOT / "CITATION.cff").read_bytes())
    lock = tmp_path / "environment.lock"
    lock.write_text("numpy==2.0.0 \\\n    --hash=sha256:00\n")
    return dict(datasets=datasets, params=params, lock=lock, config=CONFIG, results_dir=res,
                workflow=src / "Snakefile", workflow_parts=[rule], citation=src / "CITATION.cff")


def _write(tmp_path: Path, out: Path) -> dict:
    kw = _tree(tmp_path)
    sa.write_archive(out, kw.pop("datasets"), kw.pop("params"), kw.pop("lock"), kw.pop("config"), **kw)
    return kw


@pytest.fixture(scope="module")
def crate(tmp_path_factory):
    """(archive path, extracted crate root, tar member names) of one archive."""
    tmp = tmp_path_factory.mktemp("archive")
    out = tmp / "out" / "safebasins-results.tar.gz"
    _write(tmp, out)
    with tarfile.open(out) as tar:
        names = tar.getnames()
        tar.extractall(tmp / "x", filter="data")
    return out, tmp / "x" / sa.PREFIX, names


def _graph(root: Path) -> dict:
    meta = json.loads((root / sa.METADATA).read_text())
    return {e["@id"]: e for e in meta["@graph"]}


def _ids(value) -> list[str]:
    return [v["@id"] for v in (value if isinstance(value, list) else [value])]


def test_citation_cff():
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert cff["cff-version"] == "1.2.0" and cff["type"] == "software"
    assert project["dynamic"] == ["version"]            # the version's one home is the package
    assert cff["version"] == safebasins.__version__ and cff["license"] == project["license"] == "MIT"
    assert cff["authors"] and all("name" in a or "family-names" in a for a in cff["authors"])
    paper = cff["preferred-citation"]
    assert paper["type"] == "article"
    assert paper["title"] == "Analytic exploration of safe basins in a benchmark problem of forced escape"
    assert [a["family-names"] for a in paper["authors"]] == ["Karmi", "Kravetc", "Gendelman"]


def test_tarball_written_atomically(crate):
    out, _, names = crate
    assert out.is_file()
    assert [p.name for p in out.parent.iterdir()] == [out.name]  # no temporary file or directory left
    assert all(n.startswith(f"{sa.PREFIX}/") for n in names)


def test_manifest_covers_every_file(crate):
    _, root, _ = crate
    files = {p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file()}
    listed = {}
    for line in (root / sa.MANIFEST).read_text().splitlines():
        digest, name = line.split("  ", 1)
        listed[name] = digest
    assert set(listed) == files - {sa.MANIFEST}
    for name, digest in listed.items():
        assert hashlib.sha256((root / name).read_bytes()).hexdigest() == digest, name
    expected = {*TITLES, "params/fig01.yaml", "params/fig13.yaml", "config.resolved.yaml", "environment.lock",
                "environment.installed.txt", "PROVENANCE.json", "CITATION.cff", "README.md", "Snakefile",
                "workflow/rules/a.smk", sa.METADATA}
    assert set(listed) == expected
    assert yaml.safe_load((root / "config.resolved.yaml").read_text()) == CONFIG


def test_every_file_described_and_reachable(crate):
    _, root, _ = crate
    g = _graph(root)
    reachable, todo = set(), ["./"]
    while todo:
        for i in _ids(g[todo.pop()].get("hasPart", [])):
            if i not in reachable:
                reachable.add(i)
                todo.append(i)
    for p in root.rglob("*"):
        name = p.relative_to(root).as_posix()
        if not p.is_file() or name == sa.METADATA:
            continue
        assert name in g and name in reachable, name
        entity = g[name]
        assert "File" in _ids_or_types(entity) and entity.get("name") and entity.get("encodingFormat"), name
        if "sha256" in entity:  # all but the manifest, which hashes the metadata that describes it
            assert entity["sha256"] == hashlib.sha256(p.read_bytes()).hexdigest(), name
            assert int(entity["contentSize"]) == p.stat().st_size, name
        else:
            assert name == sa.MANIFEST


def _ids_or_types(entity) -> list[str]:
    t = entity["@type"]
    return t if isinstance(t, list) else [t]


def test_datasets_parameters_run_and_paper(crate):
    _, root, _ = crate
    g = _graph(root)
    for name, title in TITLES.items():
        e = g[name]
        assert e["name"] == title
        assert "application/x-netcdf" in e["encodingFormat"]
        fp = g[e["exampleOfWork"]["@id"]]
        assert "FormalParameter" in _ids_or_types(fp) and fp["workExample"]["@id"] == name
    rootds = g["./"]
    assert {"name", "description", "datePublished", "license"} <= set(rootds)
    assert set(_ids(rootds["conformsTo"])) == set(sa.PROFILES)
    assert g[rootds["license"]["@id"]]["identifier"] == "MIT"
    wf = g[rootds["mainEntity"]["@id"]]
    assert set(_ids_or_types(wf)) == {"File", "SoftwareSourceCode", "ComputationalWorkflow"}
    assert g[wf["programmingLanguage"]["@id"]]["name"] == "Snakemake"
    run = g[rootds["mentions"]["@id"]]
    assert run["@type"] == "CreateAction" and run["instrument"]["@id"] == wf["@id"] and run["endTime"]
    assert set(_ids(run["result"])) == set(TITLES)
    objects = set(_ids(run["object"]))
    assert {"config.resolved.yaml", "params/fig01.yaml", "params/fig13.yaml"} <= objects
    pv = g["#pv-config-numerics.steps_per_cycle"]
    assert pv["@type"] == "PropertyValue" and pv["value"] == 32 and pv["@id"] in objects
    software = {g[i]["name"]: g[i] for i in _ids(wf["softwareRequirements"])}
    assert {"safebasins", "Python", "numpy", "snakemake", "xarray"} <= set(software)
    assert all(s["@type"] == "SoftwareApplication" and s["softwareVersion"] for s in software.values())
    paper = g[rootds["citation"]["@id"]]
    assert paper["@type"] == "ScholarlyArticle" and paper["name"].startswith("Analytic exploration of safe basins")
    assert [g[a]["familyName"] for a in _ids(paper["author"])] == ["Karmi", "Kravetc", "Gendelman"]


def _seed_context_cache(cache: Path) -> None:
    """Put the RO-Crate 1.1 JSON-LD context into a fresh HTTP cache, so that roc-validator runs
    offline (it resolves @context through this cache).  The context is rebuilt from the one the
    rocrate package ships (RO-Crate 1.3, a superset): RO-Crate 1.1 maps these five terms to
    older IRIs, and every other 1.1 term identically."""
    import requests_cache

    ctx = json.loads((Path(rocrate.__file__).parent / "data" / "ro-crate.jsonld").read_text())
    ctx["@context"].update({
        "ComputationalWorkflow": "https://bioschemas.org/ComputationalWorkflow",
        "FormalParameter": "https://bioschemas.org/FormalParameter",
        "input": "https://bioschemas.org/ComputationalWorkflow#input",
        "output": "https://bioschemas.org/ComputationalWorkflow#output",
        "cite-as": "https://www.w3.org/ns/iana/link-relations/relation#cite-as"})
    ctx.update({"@id": CONTEXT_URL, "version": "1.1", "url": {"@id": "https://w3id.org/ro/crate/1.1"}})
    body = json.dumps(ctx).encode()
    headers = {"Content-Type": "application/ld+json"}
    resp = requests.Response()
    resp.status_code, resp.reason, resp.url, resp.encoding, resp._content = 200, "OK", CONTEXT_URL, "utf-8", body
    resp.headers = requests.structures.CaseInsensitiveDict(headers)
    resp.raw = urllib3.HTTPResponse(body=io.BytesIO(body), headers=headers, status=200, preload_content=False,
                                    request_url=CONTEXT_URL)
    resp.request = requests.Request("GET", CONTEXT_URL).prepare()
    session = requests_cache.CachedSession(cache_name=str(cache), backend="sqlite")
    session.cache.save_response(resp)
    session.close()


def _validate(root: Path, cache: Path, profile: str = "workflow-run-crate"):
    from rocrate_validator import models, services

    settings = models.ValidationSettings(rocrate_uri=str(root), profile_identifier=profile,
                                         requirement_severity="REQUIRED", offline=True, cache_path=cache)
    return services.validate(settings)


@pytest.fixture
def validator_cache(tmp_path):
    from rocrate_validator.utils.http import HttpRequester

    cache = tmp_path / "http-cache"
    _seed_context_cache(cache)
    yield cache
    HttpRequester.reset()  # the requester is a process-wide singleton bound to this cache


def test_crate_validates_offline(crate, validator_cache, tmp_path):
    _, root, _ = crate
    result = _validate(root, validator_cache)
    issues = [f"{i.check.identifier}: {i.message}" for i in result.get_issues()]
    assert result.passed(), issues
    profiles = {c.requirement.profile.identifier for c in result.executed_checks}
    assert profiles == {"ro-crate-1.1", "process-run-crate-0.5", "workflow-ro-crate-1.0",
                        "workflow-run-crate-0.5"}
    # negative control: the same crate without its CreateAction must fail (the checks really ran)
    broken = tmp_path / "broken"
    broken.mkdir()
    meta = json.loads((root / sa.METADATA).read_text())
    meta["@graph"] = [e for e in meta["@graph"] if e.get("@type") != "CreateAction"]
    for e in meta["@graph"]:
        e.pop("mentions", None)
    (broken / sa.METADATA).write_text(json.dumps(meta))
    for p in root.rglob("*"):
        if p.is_file() and p.name != sa.METADATA:
            (broken / p.relative_to(root)).parent.mkdir(parents=True, exist_ok=True)
            (broken / p.relative_to(root)).write_bytes(p.read_bytes())
    assert not _validate(broken, validator_cache).passed()


@pytest.mark.parametrize("where", ["_write_manifest", "_write_tar"])
def test_interrupted_write_leaves_nothing(tmp_path, monkeypatch, where):
    out = tmp_path / "out" / "safebasins-results.tar.gz"
    real = getattr(sa, where)

    def fail(*args):
        real(*args)  # the crate directory / part of the tarball exist when it breaks
        raise KeyboardInterrupt("killed")

    monkeypatch.setattr(sa, where, fail)
    with pytest.raises(KeyboardInterrupt):
        _write(tmp_path, out)
    assert list(out.parent.iterdir()) == []


def test_failed_rewrite_keeps_previous_archive_and_clears_leftovers(tmp_path, monkeypatch):
    out = tmp_path / "out" / "safebasins-results.tar.gz"
    out.parent.mkdir()
    out.write_bytes(b"previous")
    (out.parent / f".{out.name}.killed.tmp").write_bytes(b"half")  # leftovers of a SIGKILLed write
    (out.parent / f".{out.name}.killed.d").mkdir()
    monkeypatch.setattr(sa, "_write_tar", lambda *a: (_ for _ in ()).throw(OSError("disk full")))
    with pytest.raises(OSError):
        _write(tmp_path, out)
    assert [p.name for p in out.parent.iterdir()] == [out.name] and out.read_bytes() == b"previous"


def test_dataset_without_title_is_an_error(tmp_path):
    kw = _tree(tmp_path)
    xr.Dataset({"v": ("x", np.zeros(2))}).to_netcdf(kw["results_dir"] / "data" / "untitled.nc")
    kw["datasets"].append(kw["results_dir"] / "data" / "untitled.nc")
    out = tmp_path / "out" / "a.tar.gz"
    with pytest.raises(ValueError, match="title"):
        sa.write_archive(out, kw.pop("datasets"), kw.pop("params"), kw.pop("lock"), kw.pop("config"), **kw)
    assert list(out.parent.iterdir()) == []
