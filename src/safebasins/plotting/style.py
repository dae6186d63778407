"""Shared plotting style: rcParams, labels and symbols, number formatting, saving figures."""
from __future__ import annotations

import os
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, cast
import textwrap

import matplotlib.pyplot as plt
import numpy as np

from safebasins.plotting.data import provenance, well_texts

if TYPE_CHECKING:
    from collections.abc import Iterable, Iterator, Mapping

    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.text import Text
    from matplotlib.transforms import Bbox
    from matplotlib.typing import RcKeyType

    from safebasins.plotting.data import DataItems

DEFAULT_DPI = 180

LABELS = {
    "gamma": r"slow phase $\gamma$",
    "xi": r"averaged energy $\xi$",
    "q0": r"initial displacement $q_0$",
    "p0": r"initial momentum $p_0$",
    "q": r"displacement $q$",
    "p": r"momentum $p$",
    "Omega": r"forcing frequency $\Omega$",
    "F": r"forcing amplitude $F$",
    "F_cr": r"critical forcing $F_{cr}$",
    "t_eval": r"evaluation time $t_{eval}$ (EC)",
}

# symbols used in titles / legends for parameters
SYMBOLS = {
    "F": r"$F$",
    "Omega": r"$\Omega$",
    "Psi": r"$\Psi$",
    "xi_max": r"$\xi_{max}$",
    "q_max": r"$q_{max}$",
    "xi_ini": r"$\xi_{ini}$",
    "gamma_ini": r"$\gamma_{ini}$",
    "t_eval": r"$t_{eval}$",
    "damping": r"$\beta$",
}


SB_FACE = "0.72"        # safe basin grey (RM portraits, Figs 5-9)
SB_EDGE = "tab:red"     # safe basin boundary (Figs 5-9)
TRUNC_COLOR = "tab:blue"  # truncation level xi = xi_max (Figs 5-9, "blue dashed")

RC: dict[RcKeyType, Any] = {
    "figure.dpi": 100,
    "savefig.dpi": DEFAULT_DPI,
    "savefig.bbox": "tight",
    "font.size": 10,
    "axes.titlesize": 10,
    "axes.labelsize": 10,
    "legend.fontsize": 8,
    "legend.framealpha": 0.9,
    "xtick.direction": "in",
    "ytick.direction": "in",
    "xtick.top": True,
    "ytick.right": True,
    "axes.grid": False,
    "lines.linewidth": 1.6,
    "pdf.fonttype": 42,
}


def _rc(overrides: dict[str, Any]) -> dict[RcKeyType, Any]:
    """:data:`RC` with the caller's rcParams on top.  Their keys are checked by matplotlib when set (an
    unknown one is a KeyError naming it); its stubs spell the keys as a Literal, which a key the
    caller chose is not."""
    return {**RC, **cast("dict[RcKeyType, Any]", overrides)}


def apply_style(**overrides: Any) -> None:
    """Set the shared rcParams (call once at the top of a notebook)."""
    plt.rcParams.update(_rc(overrides))


@contextmanager
def style(**overrides: Any) -> Iterator[None]:
    with plt.rc_context(_rc(overrides)):
        yield


#: layout engine of the figures: constrained layout that also fits fixed-aspect (equal) axes, so
#: that the labels and the outside legend of an equal-aspect chart stay inside the figure whatever
#: the window's proportions (plain constrained layout lets them spill over the edges)
LAYOUT = "compressed"


def new_axes(ax: Axes | None, figsize: tuple[float, float]) -> tuple[Figure, Axes]:
    """(Figure, Axes): a new figure (layout :data:`LAYOUT`), or the figure of the given axes
    (``ax=`` of the public plotting functions; the whole figure where the axes lie in a subfigure,
    which could not be saved)."""
    if ax is None:
        fig, ax = plt.subplots(figsize=figsize, layout=LAYOUT)
        return fig, ax
    root = ax.get_figure(root=True)
    if root is None:
        raise ValueError("ax: the axes belong to no figure")
    return root, ax


def save_figure(fig: Figure, png: str | os.PathLike[str] | None = None, pdf: str | os.PathLike[str] | None = None, *,
                dpi: float = DEFAULT_DPI, datasets: Iterable[DataItems] = (), heading: str | None = None) -> Figure:
    """Write ``fig`` to PNG (``dpi``) and/or PDF, creating parent folders.

    The provenance of the datasets drawn (``datasets``: paths or Datasets, and those the
    builder attached, :func:`safebasins.plotting.data.attach`) goes into the files: PNG text
    chunks ``Source``, ``safebasins_version``, ``git_commit``, ``config_hash``, ``well``,
    ``parameters``, ... (:func:`safebasins.plotting.data.provenance`); the PDF ``Subject``.
    ``heading`` (an experiment's title) and the potential of a well other than the paper's quartic
    are written above everything drawn (:func:`add_heading`)."""
    meta = provenance(*datasets, fig=fig)
    add_heading(fig, [heading, *well_texts(*datasets, fig=fig)])
    summary = ", ".join(f"{k} {meta[k]}" for k in ("safebasins_version", "git_commit", "config_hash", "well")
                        if k in meta).replace("\n", " / ")
    for path, kw in ((png, dict(format="png", dpi=dpi, metadata=meta)),
                     (pdf, dict(format="pdf", metadata={"Subject": summary} if summary else {}))):
        if path:
            d = os.path.dirname(os.fspath(path))
            if d:
                os.makedirs(d, exist_ok=True)
            fig.savefig(path, bbox_inches="tight", **kw)
    return fig


def _drawn_extent(fig: Figure) -> Bbox:
    """Everything drawn so far, in figure coordinates (the layout applied first): a Bbox."""
    fig.draw_without_rendering()
    bb = fig.get_tightbbox()  # the renderer of fig.canvas (Figure._get_renderer)
    return bb.transformed(fig.dpi_scale_trans).transformed(fig.transFigure.inverted())


def _wrap(fig: Figure, text: object, fontsize: float, x0: float, x1: float) -> str:
    """``text`` wrapped to the width between ``x0`` and ``x1`` (figure coordinates)."""
    chars = max(40, int((x1 - x0) * fig.get_figwidth() * 72 / (0.52 * fontsize)))
    return "\n".join(textwrap.fill(line, chars) for line in str(text).split("\n"))


_HEADING_ATTR = "_safebasins_heading"


def add_heading(fig: Figure, lines: Iterable[object], *, fontsize: float = 9) -> Text | None:
    """Write ``lines`` (None and repeated lines skipped) above everything drawn on ``fig``, left-aligned
    with it, so that no title, legend or label is overlapped.  Returns the Text (None: nothing to
    write); a figure is headed once (a second call with the same lines does nothing)."""
    text = "\n".join(dict.fromkeys(str(x) for x in lines if x))
    if not text or getattr(fig, _HEADING_ATTR, None) == text:
        return None
    ext = _drawn_extent(fig)
    t = fig.text(ext.x0, ext.y1 + 0.01, _wrap(fig, text, fontsize, ext.x0, ext.x1), ha="left", va="bottom",
                 fontsize=fontsize, color="0.15")
    setattr(fig, _HEADING_ATTR, text)
    return t


def add_footnote(fig: Figure, text: object, *, fontsize: float = 7.5) -> Text:
    """Write ``text`` below everything drawn on ``fig`` (a key to the symbols of a legend, why a panel
    is empty), wrapped to the width of the drawing; each footnote goes below the previous ones."""
    ext = _drawn_extent(fig)
    return fig.text(ext.x0, ext.y0 - 0.01, _wrap(fig, text, fontsize, ext.x0, ext.x1), ha="left", va="top",
                    fontsize=fontsize, color="0.25")


def fmt_value(v: Any, name: str | None = None) -> str:
    """Compact number for titles; multiples of pi are written with pi."""
    try:
        v = float(v)
    except (TypeError, ValueError):
        return str(v)
    if not np.isfinite(v):
        return str(v)
    if name in ("Psi", "gamma_ini") and v != 0:
        r = v / np.pi
        for num, txt in ((1, r"\pi"), (0.5, r"\pi/2"), (-1, r"-\pi"), (-0.5, r"-\pi/2"), (2, r"2\pi")):
            if abs(r - num) < 1e-9:
                return f"${txt}$"
    if v != 0 and (abs(v) < 1e-3 or abs(v) >= 1e5):
        return f"{v:.3g}"
    return f"{v:.6g}" if abs(v) >= 1 else f"{round(v, 6):g}"


def param_text(params: Mapping[str, Any], *, sep: str = ", ") -> str:
    """``{"F": 0.0876, "Omega": 0.92}`` -> ``$F$ = 0.0876, $\\Omega$ = 0.92``."""
    parts = []
    for k, v in params.items():
        if v is None:
            continue
        parts.append(f"{SYMBOLS.get(k, k)} = {fmt_value(v, k)}")
    return sep.join(parts)


def plain_text(txt: str) -> str:
    """Mathtext of titles and legends (``$\\xi_{max}$ = 0.18, $\\Psi$ = $\\pi$``) as plain text for
    captions (``ξ_max = 0.18, Ψ = π``)."""
    for a, b in (("$\\xi_{max}$", "ξ_max"), ("$\\xi_{ini}$", "ξ_ini"), ("$\\gamma_{ini}$", "γ_ini"),
                 ("$\\Psi$", "Ψ"), ("$\\beta$", "β"), ("$\\Omega$", "Ω"), ("$q_{max}$", "q_max"),
                 ("$t_{eval}$", "t_eval"), ("\\pi", "π"), ("$", "")):
        txt = txt.replace(a, b)
    return txt


def pi_ticks(ax: Axes, lo: float, hi: float, axis: str = "x") -> None:
    """Ticks at multiples of pi/2 between lo and hi."""
    k = np.arange(np.ceil(lo / (np.pi / 2) - 1e-9), np.floor(hi / (np.pi / 2) + 1e-9) + 1)
    names = {0: "0", 1: r"$\pi/2$", -1: r"$-\pi/2$", 2: r"$\pi$", -2: r"$-\pi$", 3: r"$3\pi/2$",
             -3: r"$-3\pi/2$", 4: r"$2\pi$", -4: r"$-2\pi$"}
    ticks = k * np.pi / 2
    labels = [names.get(int(i), f"{int(i)}" + r"$\pi/2$") for i in k]
    if axis == "x":
        ax.set_xticks(ticks, labels)
    else:
        ax.set_yticks(ticks, labels)


def grey_levels(n: int, light: float = 0.86, dark: float = 0.32) -> list[str]:
    """n grey shades, lightest first."""
    if n <= 1:
        return [str(round((light + dark) / 2, 3))]
    return [str(round(v, 3)) for v in np.linspace(light, dark, n)]
