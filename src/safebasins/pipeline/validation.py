"""Config errors and the checks JSON Schema cannot express; every message names the key.

Messages read ``config key figures.fig13.xi_max[2]: <what is wrong and what to do>``.
"""
from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, NoReturn

if TYPE_CHECKING:
    from safebasins.wells.base import Well


class ConfigError(ValueError):
    """A configuration error; the message starts with the offending key."""


def key_path(path: Iterable[str | int]) -> str:
    """Dotted key of a JSON path: ``("figures", "fig13", "xi_max", 2)`` -> ``figures.fig13.xi_max[2]``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or "<config>"


def fail(key: str, msg: str) -> NoReturn:
    raise ConfigError(f"config key {key}: {msg}")


def indexed(key: str, values: Any, i: int) -> str:
    """``key[i]`` when the config value is a list, else ``key``."""
    return f"{key}[{i}]" if isinstance(values, (list, tuple)) else key


@dataclass
class CheckContext:
    """What a kind's ``check`` may consult: the whole config, and the kind and config block of
    every experiment by name (for cross-references between experiments)."""

    config: dict[str, Any]
    kinds: dict[str, str]              # experiment name -> kind name
    blocks: dict[str, dict[str, Any]]  # experiment name -> its (default-filled) config block
    keys: dict[str, str]               # experiment name -> its dotted config key
    _wells: dict[str, Well] = field(default_factory=dict)   # well spec -> well object (built once)

    def block(self, experiment: str) -> dict[str, Any]:
        return self.blocks[experiment]

    def well(self, experiment: str) -> Well:
        """The experiment's well (safebasins.wells); an invalid well is an error naming ``<key>.well``."""
        from safebasins import wells

        spec = wells.spec_of(self.blocks[experiment]["well"])
        key = repr(spec)
        if key not in self._wells:
            try:
                self._wells[key] = wells.from_spec(spec, self.config["fourier"] if spec["name"] == "quartic" else None)
            except ValueError as exc:
                fail(f"{self.keys[experiment]}.well", f"not a potential well: {exc}")
        return self._wells[key]

    def well_at(self, key: str) -> Well:
        """The well of the experiment at dotted config key ``key`` (what a kind's ``check`` gets)."""
        (name,) = [n for n, k in self.keys.items() if k == key]
        return self.well(name)

    @property
    def tiles(self) -> int:
        return int(self.config["numerics"]["tiles"])

    fail = staticmethod(fail)

    def check_range(self, key: str, r: Mapping[str, Any], *, positive: bool = False) -> None:
        start, stop = float(r["start"]), float(r["stop"])
        num, step = r.get("num"), r.get("step")
        if num is not None and step is not None:
            fail(key, f"give either num ({num}) or step ({step}), not both; an override file merged into "
                      "config.yaml keeps the key it does not mention: set the other one to null there "
                      "(e.g. `num: null`)")
        if num is None and step is None:
            fail(key, "give num (number of points, endpoints included) or step (spacing from start to stop)")
        if not stop > start:
            fail(key, f"empty range: stop ({stop}) must be greater than start ({start})")
        if step is not None:
            k = (stop - start) / step
            if step > stop - start:
                fail(f"{key}.step", f"step {step} is larger than the range [{start}, {stop}]")
            if abs(k - round(k)) > 1e-9 * max(1.0, k):
                last = start + math.floor(k + 1e-9) * step
                fail(key, f"stop {stop} is not reached by whole steps of {step} from {start} (the last value "
                          f"would be {last:.12g}): make stop = start + k * step or give num instead")
        if positive and start <= 0:
            fail(f"{key}.start", f"must be > 0, got {start}")

    def check_unique(self, key: str, values: Any) -> None:
        """A list that becomes a coordinate must not repeat a value."""
        if isinstance(values, (list, tuple)):
            seen: set[Any] = set()
            for i, v in enumerate(values):
                if v in seen:
                    fail(f"{key}[{i}]", f"{v!r} is listed twice: each value is one point of a coordinate")
                seen.add(v)

    def check_interval(self, key: str, iv: Sequence[float]) -> None:
        lo, hi = iv
        if not hi > lo:
            fail(key, f"empty interval [{lo}, {hi}]: the second value must be greater than the first")

    def check_grid(self, key: str, g: Mapping[str, Any]) -> None:
        self.check_interval(f"{key}.q0", g["q0"])
        self.check_interval(f"{key}.p0", g["p0"])
        n = g["n"]
        nq = n if isinstance(n, int) else n[0]
        if self.tiles > nq:
            fail("numerics.tiles", f"{self.tiles} tiles but {key} has only {nq} q0 rows")

    def check_thresholds_below_separatrix(self, key: str, values: float | list[float] | tuple[float, ...], what: str,
                                          well: Well, damping: float | list[float] | tuple[float, ...] = 0.0) -> None:
        """Analytic products of the undamped slow flow need xi_max below the well's barrier energy
        (``Well.check_analytic_threshold``, the library's one rule); a damped one (``damping`` > 0: a
        value, or one per curve like ``values``) takes xi_max = E_b, as the numerics do."""
        top = well.barrier_energy
        xs = values if isinstance(values, (list, tuple)) else [values]
        betas = damping if isinstance(damping, (list, tuple)) else [damping]
        for i in range(max(len(xs), len(betas))):
            x, beta = xs[i if len(xs) > 1 else 0], betas[i if len(betas) > 1 else 0]
            where = indexed(key, values, i if len(xs) > 1 else 0)
            try:
                (well.check_threshold if beta > 0 else well.check_analytic_threshold)("xi_max", x)
            except ValueError as exc:
                if beta > 0:
                    fail(where, f"{what} (damping {beta:g}): {exc}")
                fail(where, f"{what} needs xi_max < {top:.6g}, the barrier energy of the {well.name} well (the "
                            f"action-angle map is singular on the separatrix), got {x!r}"
                            + (" (within a relative 1e-12 of it, which counts as at it)" if x < top else ""))

    def check_t_eval_within(self, key: str, t_eval: float | list[float] | tuple[float, ...], cycles: float) -> None:
        t = t_eval if isinstance(t_eval, (list, tuple)) else [t_eval]
        if max(t) > cycles:
            fail(key, f"evaluation time {max(t)} beyond the horizon cycles = {cycles}")
