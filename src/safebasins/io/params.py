"""The hash of one experiment's resolved parameters (the datasets' ``config_hash``): standard
library only, so the pipeline's ``parameters`` jobs stay light."""
from __future__ import annotations

import hashlib
import json
from typing import Any


def params_hash(params: dict[str, Any]) -> str:
    """SHA-256 of the canonical JSON of one experiment's resolved parameters."""
    return hashlib.sha256(json.dumps(params, sort_keys=True, separators=(",", ":")).encode()).hexdigest()
