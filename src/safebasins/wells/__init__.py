"""Potential wells: V, dV, H0, barriers, turning points and action-angle data (wells.base).

``QUARTIC`` is the paper's well (closed forms, wells.quartic); ``cubic()`` the escape equation
V = q^2/2 - q^3/3 and ``polynomial(coefficients)`` any polynomial well (numeric action-angle,
wells.numeric, wells.polynomial).  :func:`resolve_well` is how the theory reads its
``well=`` / ``fourier=`` arguments; :func:`from_spec` how the pipeline reads a config's ``well:``.
"""
from safebasins.wells.base import Well
from safebasins.wells.quartic import FOURIER_VARIANTS, QUARTIC, QuarticWell
# (bound here, after the submodule import, so the package attribute is the function)
from safebasins.wells.polynomial import cubic, polynomial  # noqa: E402

__all__ = ["Well", "QuarticWell", "QUARTIC", "resolve_well", "from_spec", "from_attrs", "spec_attrs", "well_attrs", "spec_of", "cubic", "polynomial"]


def resolve_well(well=None, fourier=None) -> Well:
    """The well of a theory call: the quartic with the paper's first harmonic by default;
    ``fourier`` ("paper" | "exact") selects the quartic's G (eq 20 as printed or exact) and is
    an error with any other well (they carry their exact first harmonic)."""
    if fourier is not None and fourier not in FOURIER_VARIANTS:
        raise ValueError(f"fourier must be one of {FOURIER_VARIANTS}, got {fourier!r}")
    if well is None:
        return QUARTIC if fourier in (None, "paper") else QuarticWell(fourier)
    if not isinstance(well, Well):
        raise ValueError(f"well must be a safebasins.wells.Well, got {well!r}")
    if isinstance(well, QuarticWell):
        return well if fourier is None or fourier == well.fourier else QuarticWell(fourier)
    if fourier is not None:
        raise ValueError(f"fourier selects the quartic's first harmonic (eq 20 or exact); the {well.name} well "
                         "uses its exact first harmonic: leave fourier out")
    return well


def from_spec(spec, fourier=None) -> Well:
    """A well from a resolved config spec: ``{"name": "quartic"}``, ``{"name": "cubic"}`` or
    ``{"name": "polynomial", "coefficients": [...]}``."""
    name = spec["name"]
    if name == "quartic":
        return resolve_well(None, fourier)
    if name == "cubic":
        return cubic()
    if name == "polynomial":
        return polynomial(spec["coefficients"])
    raise ValueError(f"unknown well {name!r} (quartic, cubic, polynomial)")


def spec_attrs(spec) -> dict:
    """Dataset attributes naming a well spec: ``well`` and, for a polynomial, ``well_coefficients``."""
    out = {"well": spec["name"]}
    if spec["name"] == "polynomial":
        out["well_coefficients"] = [float(c) for c in spec["coefficients"]]
    return out


def well_attrs(well: Well) -> dict:
    """Dataset attributes naming a well object (:func:`spec_attrs` of its spec)."""
    spec = {"name": well.name}
    if well.name == "polynomial":
        spec["coefficients"] = well.coefficients
    return spec_attrs(spec)


def from_attrs(attrs) -> Well:
    """The well a dataset was made with (its :func:`spec_attrs` attributes)."""
    name = attrs["well"]
    spec = {"name": name}
    if name == "polynomial":
        spec["coefficients"] = [float(c) for c in attrs["well_coefficients"]]
    return from_spec(spec)


def spec_of(config_value) -> dict:
    """Resolved spec of a config ``well:`` value (``quartic``, ``cubic``, ``{polynomial: [...]}``)."""
    if isinstance(config_value, str):
        return {"name": config_value}
    (name, coefficients), = config_value.items()
    return {"name": name, "coefficients": [float(c) for c in coefficients]}
