"""Report captions written at render time (safebasins.plotting.captions)."""
from __future__ import annotations


def test_caption_is_rst_inside_a_jinja_raw_block():
    import docutils.core
    import jinja2
    from matplotlib.figure import Figure

    from safebasins.plotting.captions import add_note, caption_rst, notes

    fig = Figure()
    add_note(fig, "9,250 of 90,000 pixels {{ not a template }} *stay* safe")
    assert notes(fig) == ["9,250 of 90,000 pixels {{ not a template }} *stay* safe"]
    text = caption_rst(label="Fig. 1", paper="quoted", look="drawn", data_notes=notes(fig),
                       notebook="notebooks/x.ipynb", datasets=["results/data/x.nc"])
    rendered = jinja2.Environment(trim_blocks=True, lstrip_blocks=True).from_string(text).render()
    assert "{{ not a template }}" in rendered  # Snakemake's Jinja2 pass leaves it alone
    html = docutils.core.publish_parts(rendered, writer="html")["body"]
    assert "9,250 of 90,000 pixels" in html and "<strong>Paper:</strong>" in html and "*stay*" in html
