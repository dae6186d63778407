#!/usr/bin/env python
"""Write the notebooks of the package's figures (the paper's 22 and the beyond-the-paper ones)
from the registry.  (Their report captions are written by the notebooks themselves at render
time, with the numbers read from the datasets: results/captions/<name>.rst.)

    .venv/bin/python scripts/make_notebooks.py            # (re)write notebooks/
    .venv/bin/python scripts/make_notebooks.py --check    # exit 1 if any file is out of date
    .venv/bin/python scripts/make_notebooks.py --gallery results/figures
                                   # also write small copies of the built PNGs to docs/figures/

Source of truth: the experiments of ``safebasins.pipeline.catalog`` as resolved from
config/config.yaml (datasets, options, captions) and ``safebasins.plotting`` (the drawing);
the notebook layout is ``safebasins.plotting.notebooks``.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from safebasins.pipeline.plan import plan
from safebasins.plotting.notebooks import notebook_text

ROOT = Path(__file__).resolve().parents[1]


def packaged_figures():
    return [f for f in plan(ROOT / "config" / "config.yaml").figures() if f.packaged]


def outputs():
    for fig in packaged_figures():
        yield ROOT / fig.notebook, notebook_text(fig)


def rst_to_markdown(text: str) -> str:
    """A report caption (results/captions/<name>.rst: reST inside a Jinja raw block) as Markdown."""
    text = text.replace("{% raw %}", "").replace("{% endraw %}", "").strip()
    return text.replace("``", "`")  # reST's backslash escapes (\\*, \\|) mean the same in Markdown


def gallery_entries(src: Path):
    """(section, heading, file stem, caption) of every gallery image in report order; the caption
    is the one the figure's notebook wrote with the numbers of the run (results/captions/), else
    the paper's."""
    for fig in packaged_figures():
        cap = src.parent / "captions" / f"{fig.name}.rst"
        text = rst_to_markdown(cap.read_text()) if cap.exists() else fig.caption
        yield (None if fig.category == "Figures" else fig.category), fig.label, fig.name, text


def write_gallery(src: Path, width: int = 800):
    """docs/figures/<stem>.png: downscaled copies of the pipeline's PNGs (+ an index)."""
    from PIL import Image

    out = ROOT / "docs" / "figures"
    out.mkdir(parents=True, exist_ok=True)
    lines = ["# Figure gallery", "",
             f"Downscaled ({width} px wide) copies of `results/figures/figNN.png` and "
             "`results/figures/extra_<name>.png` as built by `snakemake figures` and `snakemake extras` at "
             "paper resolution (config/config.yaml).", "",
             "How the figures are made:", "",
             "- drawing: `src/safebasins/plotting/` (one module per figure family: `fcr`, `basins`, `charts`, "
             "`maps`, `extras`);",
             "- experiments and their figure texts (datasets, options, paper caption, what to look for): "
             "`src/safebasins/pipeline/catalog.py`, resolved through the registry of kinds "
             "(`src/safebasins/pipeline/kinds/`);",
             "- `.venv/bin/python scripts/make_notebooks.py` regenerates `notebooks/*.ipynb` (`--check` verifies "
             "they are current); each notebook writes its report caption `results/captions/<name>.rst` with the "
             "numbers read from the datasets;",
             "- `snakemake results/figures/figNN.png` runs one notebook with papermill (`-k python3`) and keeps "
             "the executed copy in `results/notebooks/`; `snakemake figures` builds all 22, `snakemake extras` "
             "the three extra ones;",
             "- `scripts/make_notebooks.py --gallery results/figures` refreshes this page.", ""]
    section = None
    for sec, heading, stem, caption in gallery_entries(src):
        png = src / f"{stem}.png"
        if not png.exists():
            print(f"gallery: missing {png}")
            continue
        if sec != section:
            lines += [f"# {sec}", ""]
            section = sec
        im = Image.open(png).convert("RGB")
        h = round(im.height * width / im.width)
        im.resize((width, h), Image.LANCZOS).quantize(colors=128).save(out / f"{stem}.png", optimize=True)
        lines += [f"## {heading}", "", caption, "", f"![{stem}]({stem}.png)", ""]
    (out / "README.md").write_text("\n".join(lines))
    print(f"gallery written to {out.relative_to(ROOT)}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="only report files that differ")
    ap.add_argument("--gallery", type=Path, metavar="FIGURE_DIR",
                    help="also write downscaled PNGs from FIGURE_DIR to docs/figures/")
    args = ap.parse_args(argv)
    if args.gallery:
        write_gallery(args.gallery)
    stale = []
    for path, text in outputs():
        if path.exists() and path.read_text() == text:
            continue
        stale.append(path)
        if not args.check:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
    verb = "out of date" if args.check else "written"
    for p in stale:
        print(f"{verb}: {p.relative_to(ROOT)}")
    if args.check and stale:
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
