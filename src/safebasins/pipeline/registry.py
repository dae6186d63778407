"""The registry of experiment kinds: one declarative entry per kind of computation.

A *kind* (a :class:`Kind` subclass registered with :func:`register`) says everything the
pipeline needs about one kind of experiment:

* ``schema``   the JSON schema of its config block (defaults live there, nowhere else);
* ``check``    the checks JSON Schema cannot express (each failure names the config key);
* ``resolve``  config block -> resolved parameters (``results/params/<experiment>.yaml``);
* ``products`` the datasets it makes: path, stage, inputs and the library call that builds it;
* ``tasks`` / ``chart_ics``  its escape-chart tile jobs, if any (rule ``chart_tile``);
* ``cost``     upper-bound trajectory-steps (cost estimate, cluster resources);
* ``builder`` / ``figure_inputs``  its figure (papermill notebook, report entry).

An *experiment* is one instance of a kind: the paper's figures and the beyond-the-paper
products are declared in :mod:`safebasins.pipeline.catalog`; further experiments can be
declared in the config under ``experiments:`` with their ``kind``.  The Snakefile, the rule
scripts, the notebook generator, the cost estimate and the report all read :func:`plan`.
Adding a kind = one entry (docs/adding-an-experiment.md) + its library call + its plotting
function.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any, ClassVar, TypeAlias, TypeVar

import numpy as np

from safebasins.pipeline.values import base_well, damping, grid_axes, tile_slice
from safebasins.pipeline.well_defaults import WellDefault

if TYPE_CHECKING:
    import xarray as xr
    from numpy.typing import NDArray

    from safebasins.pipeline.validation import CheckContext

__all__ = ["Kind", "Job", "ResolveContext", "chart_tile", "Product", "FigureSpec", "Experiment", "KINDS", "register",
           "STAGES", "Block", "Params",
           "Inputs", "Build", "Contract", "FigureInputs", "ChartICs"]

#: dataset stages and their directories under results/data
STAGES = {"analytic": "results/data/analytic", "numeric": "results/data/numeric", "extras": "results/data/extras"}
PARAMS_DIR = "results/params"
PARTS_DIR = "results/data/numeric/parts"
FIGURE_DIR = "results/figures"


@dataclass(frozen=True)
class ResolveContext:
    """Global settings a kind's ``resolve`` may use."""

    fourier: str         # the config's fourier for the quartic; "exact" for every other well
    well: dict[str, Any]  # the experiment's well spec (safebasins.wells.spec_of)
    steps_per_cycle: int
    seed: int            # the config seed plus this experiment's offset


#: one experiment's config block (YAML data, the schema's defaults filled in)
Block: TypeAlias = dict[str, Any]
#: one experiment's resolved parameters (plain YAML data: results/params/<experiment>.yaml)
Params: TypeAlias = dict[str, Any]
#: the datasets a product reads, loaded (:func:`safebasins.pipeline.runtime.load_inputs`): name -> a
#: Dataset or a list of them; ``tiles``: one list of tile Datasets per chart task
Inputs: TypeAlias = dict[str, Any]
#: a product's library call ``build(params, inputs, job)`` returning its Dataset
Build: TypeAlias = "Callable[[Params, Inputs, Job], xr.Dataset]"
#: the variables of a dataset that readers rely on -> their dims (docs/contracts.md)
Contract: TypeAlias = dict[str, tuple[str, ...]]
#: a figure's notebook parameters: name -> dataset path, or a list of paths
FigureInputs: TypeAlias = Mapping[str, str | list[str]]
#: the ICs of a kind's chart tasks: ``(q0, p0, grid)``, grid axes (grid=True) or paired samples
ChartICs: TypeAlias = "tuple[NDArray[np.float64], NDArray[np.float64], bool]"


def params_path(experiment: str) -> str:
    return f"{PARAMS_DIR}/{experiment}.yaml"


def dataset_path(stage: str, name: str) -> str:
    return f"{STAGES[stage]}/{name}.nc"


@dataclass(frozen=True)
class Job:
    """How a job computes (never what): numba threads (None: all) and the numerics backend."""

    threads: int | None = 1
    backend: str = "cpu"


@dataclass(frozen=True)
class Product:
    """One dataset of an experiment.

    ``build(params, inputs, job)`` returns the Dataset (the runtime adds CF/provenance
    attributes with ``title`` and ``history`` and writes it atomically; ``job`` is a :class:`Job`:
    numba threads and numerics backend, which never change a result); ``inputs`` maps names
    to the files it reads besides the experiment's parameter file (tiles, other datasets);
    ``heavy`` products run with ``numerics.threads`` numba threads; ``tiles`` products read
    the chart tiles of their experiment (``inputs["tiles"]``, tasks x tiles, task-major).
    ``contract`` names the variables readers rely on and their dims (docs/contracts.md; the
    tests check it on every dataset of the quick run).
    """

    path: str
    stage: str
    build: Build
    title: str
    history: str
    inputs: Mapping[str, object] = field(default_factory=dict)
    heavy: bool = False
    tiles: bool = False
    contract: Mapping[str, tuple[str, ...]] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.path.rsplit("/", 1)[1].removesuffix(".nc")


@dataclass(frozen=True)
class FigureSpec:
    """One figure: a papermill notebook calling ``builder`` on ``inputs`` (dataset paths)."""

    name: str            # results/figures/<name>.png|pdf
    stem: str            # notebook file stem
    builder: str         # "safebasins.plotting.<module>:<function>"
    inputs: FigureInputs
    options: Mapping[str, object]
    caption: str         # the paper's caption (or what the figure shows)
    look: str            # what to look for
    label: str           # report label ("Fig. 13", a title)
    category: str        # report category
    packaged: bool       # notebook committed under notebooks/ (else generated under results/)

    @property
    def png(self) -> str:
        return f"{FIGURE_DIR}/{self.name}.png"

    @property
    def pdf(self) -> str:
        return f"{FIGURE_DIR}/{self.name}.pdf"

    @property
    def notebook(self) -> str:
        """The papermill template notebook."""
        return f"notebooks/{self.stem}.ipynb" if self.packaged else f"results/notebooks/templates/{self.stem}.ipynb"

    @property
    def executed_notebook(self) -> str:
        return f"results/notebooks/{self.stem}.ipynb"

    def dataset_files(self) -> list[str]:
        return [x for v in self.inputs.values() for x in (v if isinstance(v, (list, tuple)) else [v])]


class Kind:
    """Base of every experiment kind (see the module docstring); subclasses set the class
    attributes and override what they make."""

    name: ClassVar[str]
    description: ClassVar[str]
    schema: ClassVar[dict[str, Any]]
    #: plotting function of its figure, "safebasins.plotting.<module>:<function>" (None: no figure)
    builder: ClassVar[str | None] = None
    #: False: the kind is written for the paper's quartic only (a config naming another well
    #: for it is rejected); True: it takes the experiment's ``well:`` (params["well"])
    any_well: ClassVar[bool] = True
    #: True: the kind integrates/averages the damped equation q'' + beta q' + V'(q) = ... with the
    #: experiment's ``damping`` (params["damping"], safebasins.pipeline.values.damping); False: a
    #: config with damping > 0 for it is refused, naming the key
    damped: ClassVar[bool] = False
    #: config keys whose schema default is null and whose value follows the experiment's well:
    #: key -> the quartic's value carried over by the well's own scale (pipeline.well_defaults),
    #: filled in before ``check``
    well_defaults: ClassVar[dict[str, WellDefault]] = {}

    def check(self, block: Block, key: str, ctx: CheckContext) -> None:
        """Checks beyond the schema; raise ``ctx.fail(key + ".field", message)``."""

    def resolve(self, block: Block, ctx: ResolveContext) -> Params:
        raise NotImplementedError

    def products(self, experiment: str, params: Params) -> list[Product]:
        return []

    def tasks(self, params: Params) -> list[dict[str, Any]]:
        """Escape-chart tasks (one chart each), split into tile jobs by ``numerics.tiles``: kinds
        that integrate charts resolve them into ``params["tasks"]`` (each with ``F``,
        ``xi_max``, ``q_max`` lists and optionally ``Psi``)."""
        return list(params.get("tasks", ()))

    def chart_ics(self, params: Params) -> ChartICs:
        """``(q0, p0, grid)`` of the chart tasks: grid axes (grid=True) or paired samples."""
        raise NotImplementedError(f"kind {self.name!r} has no escape-chart tasks")

    def compute_tile(self, params: Params, task: int, tile: int, tiles: int, job: Job) -> xr.Dataset:
        """One job of the ``chart_tile`` rule: by default tile ``tile`` of ``tiles`` (a block of q0
        rows or samples) of the escape chart of task ``task``."""
        return chart_tile(self, params, task, tile, tiles, job)

    def cost(self, params: Params) -> int:
        """Upper bound of the trajectory-steps its numerics integrate (no early escape)."""
        return 0

    def figure_inputs(self, experiment: str, params: Params) -> FigureInputs:
        """Notebook parameter name -> dataset path(s) of its figure."""
        return {}

    def default_figure_text(self, experiment: str, params: Params) -> tuple[str, str]:
        """(caption, what to look for) of a figure not described in the catalog."""
        return self.description, self.description


class GridChartKind(Kind):
    """A kind whose chart tasks all integrate the experiment's (q0, p0) grid ``params["grid"]``."""

    def chart_ics(self, params: Params) -> ChartICs:
        q0, p0 = grid_axes(params["grid"])
        return q0, p0, True

    def cost(self, params: Params) -> int:
        nq, np_ = params["grid"]["n"]
        return len(params["tasks"]) * nq * np_ * params["cycles"] * params["steps_per_cycle"]


KINDS: dict[str, Kind] = {}

K = TypeVar("K", bound=Kind)


def register(cls: type[K]) -> type[K]:
    """Class decorator: add a kind to the registry (its ``name`` must be new)."""
    name = cls.name
    if name in KINDS and type(KINDS[name]) is not cls:
        raise ValueError(f"experiment kind {name!r} is registered twice ({type(KINDS[name]).__name__}, {cls.__name__})")
    KINDS[name] = cls()
    return cls


@dataclass(frozen=True)
class Experiment:
    """One experiment of a run: its name, kind, config location and resolved parameters."""

    name: str
    kind: Kind
    key: str                 # dotted config key of its block, for messages
    params: Params
    figure: FigureSpec | None
    products: tuple[Product, ...]
    tasks: tuple[dict[str, Any], ...]

    @property
    def params_file(self) -> str:
        return params_path(self.name)

    def dataset_files(self) -> list[str]:
        return [p.path for p in self.products]


def chart_tile(kind: Kind, params: Params, k: int, tile: int, tiles: int, job: Job) -> xr.Dataset:
    """The default tile job of escape-chart tasks (rule ``chart_tile``, :meth:`Kind.compute_tile`):
    tile ``tile`` of ``tiles`` of task ``k``.  Grid tasks: a contiguous block of q0 rows x all p0
    (dims q0, p0); paired ICs: a contiguous block of the samples (dim ``sample``, global index).  A
    task may carry its own forcing phase ``Psi`` or frequency ``Omega``.  Each trajectory is
    independent: the gathered chart is the same for any tile count."""
    from safebasins.numerics import escape_chart

    task = kind.tasks(params)[k]
    Psi = task.get("Psi", params.get("Psi"))
    Omega = task.get("Omega", params.get("Omega"))
    if Omega is None or Psi is None:
        raise ValueError(f"experiment {params['experiment']!r}, chart task {k}: no forcing "
                         f"{'frequency Omega' if Omega is None else 'phase Psi'} in the task or the parameters")
    q0, p0, grid = kind.chart_ics(params)
    sl = tile_slice(q0.size, tiles, tile)
    q0 = q0[sl]
    p0 = p0 if grid else p0[sl]
    print(f"{params['experiment']} task {k} tile {tile}/{tiles}: F={task['F']} Omega={Omega} Psi={Psi} "
          f"xi_max={task['xi_max']} q_max={task['q_max']} cycles={params['cycles']} "
          f"ICs={q0.size}x{p0.size if grid else 1}", flush=True)
    ds = escape_chart(q0, p0, task["F"], Omega, Psi, xi_max=tuple(task["xi_max"]), q_max=tuple(task["q_max"]),
                      cycles=params["cycles"], steps_per_cycle=params["steps_per_cycle"], threads=job.threads,
                      grid=grid, backend=job.backend, well=base_well(params),
                      damping=damping(params))
    if not grid:
        ds = ds.assign_coords(sample=np.arange(sl.start, sl.stop))
    return ds
