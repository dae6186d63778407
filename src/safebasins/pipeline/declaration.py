"""One experiment's declaration in the catalog (:mod:`safebasins.pipeline.catalog`): its config
block, kind, seed offset and figure texts."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Declaration:
    name: str                 # experiment name: results/params/<name>.yaml, results/figures/<name>.png
    kind: str
    key: tuple[str, str]      # config block: config[key[0]][key[1]]
    title: str
    stem: str                 # notebook stem (notebooks/<stem>.ipynb)
    label: str                # report label
    category: str             # report category
    caption: str
    look: str
    options: dict[str, Any] = field(default_factory=dict)
    seed_offset: int = 0      # experiments never share random streams: seed = config seed + offset
