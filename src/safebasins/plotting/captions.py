"""Report captions written at render time: the figure notebook writes the caption the Snakemake
report shows (``results/captions/<name>.rst``), so every number in it is read from the datasets.

A figure builder attaches what the data show to the Figure it returns (:func:`add_note`, one
sentence each; builders compute them from the same datasets they draw); the notebook then calls
:func:`write_caption` with the figure's texts from the catalog: the paper's caption (quoted),
what is drawn (no numbers: those come from the data) and the notes.  Snakemake renders a
caption through Jinja2 before docutils, so the text is wrapped in a ``raw`` block.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, SupportsInt

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

    import numpy.typing as npt
    from matplotlib.figure import Figure

    from safebasins.plotting.data import DataItem, DataItems

__all__ = ["add_note", "notes", "caption_rst", "write_caption", "count", "fmt_range"]

_ATTR = "_safebasins_notes"


def add_note(fig: Figure, text: str | None) -> Figure:
    """Attach one sentence about the data to a Figure (shown in its report caption; None: nothing)."""
    if text:
        if not getattr(fig, _ATTR, None):
            setattr(fig, _ATTR, [])
        getattr(fig, _ATTR).append(str(text).strip())
    return fig


def notes(fig: Figure) -> list[str]:
    return list(getattr(fig, _ATTR, None) or [])


def count(n: SupportsInt, one: str, many: str | None = None) -> str:
    """``count(3, "orbit")`` -> ``"3 orbits"``."""
    n = int(n)
    return f"{n:,} {one if n == 1 else (many or one + 's')}"


def fmt_range(values: npt.ArrayLike, fmt: str = "{:.4g}") -> str:
    """``"a-b"`` of the finite values (one value: ``"a"``)."""
    v = np.asarray(values, float).ravel()
    v = v[np.isfinite(v)]
    if not v.size:
        return "n/a"
    lo, hi = fmt.format(v.min()), fmt.format(v.max())
    return lo if lo == hi else f"{lo}-{hi}"


def _rst_escape(text: str) -> str:
    return text.replace("*", r"\*").replace("`", r"\`").replace("|", r"\|")


def caption_rst(*, label: str, look: str, paper: str | None = None, shows: str | None = None,
                data_notes: Sequence[str] = (), notebook: str | os.PathLike[str] | None = None,
                datasets: Iterable[str | os.PathLike[str] | None] = ()) -> str:
    """The report caption (reStructuredText inside a Jinja2 ``raw`` block).

    label : "Fig. 18" (report label); paper : the paper's caption (quoted), or shows : what a
    figure beyond the paper shows (exactly one of the two); look : what is drawn; data_notes :
    sentences read from the datasets.
    """
    if paper is not None and shows is None:
        lead = f"**Paper:** {_rst_escape(paper)}"
    elif shows is not None and paper is None:
        lead = f"**Shows:** {_rst_escape(shows)}"
    else:
        raise ValueError("give exactly one of paper (the paper's caption) and shows (a figure beyond the paper)")
    parts = [f"{label}. {lead}", f"**Drawn:** {_rst_escape(look)}"]
    if data_notes:
        parts.append("**In our data:**\n\n" + "\n".join(f"- {_rst_escape(n)}" for n in data_notes))
    files = [str(d) for d in datasets if d is not None]
    if notebook or files:
        parts.append(("Notebook ``" + str(notebook) + "``; " if notebook else "")
                     + "datasets " + ", ".join(f"``{f}``" for f in files) + ".")
    return "{% raw %}\n" + "\n\n".join(parts) + "\n{% endraw %}\n"


def write_caption(path: str | os.PathLike[str] | None, fig: Figure, *, label: str, look: str, paper: str | None = None,
                  shows: str | None = None, notebook: str | os.PathLike[str] | None = None,
                  datasets: Iterable[DataItems] = ()) -> str | None:
    """Write the caption of ``fig`` (its :func:`notes`) to ``path`` (parent folders created)."""
    if not path:
        return None
    flat: list[DataItem] = []
    for d in datasets:
        flat += list(d) if isinstance(d, (list, tuple)) else [d]
    text = caption_rst(label=label, paper=paper, shows=shows, look=look, data_notes=notes(fig), notebook=notebook,
                       datasets=[os.fspath(d) for d in flat if isinstance(d, (str, os.PathLike))])
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_text(text)
    return text
