"""The potential well: the one home of V, dV, H0, turning points, barriers and the unforced
motion's action-angle variables (paper Sec. 2.1, generalised to any well).

A well is a potential ``V(q)`` with its minimum at ``q = 0``: ``V(0) = V'(0) = 0``,
``V''(0) > 0``.  On each side the well ends in one of three ways:

* at a barrier (a local maximum of V, i.e. a saddle of H0) at ``q_b``: escape energy ``V(q_b)``;
* open at infinity: ``V'`` keeps its sign and V tends to a finite limit ``A`` (Morse, sech^2):
  escape energy ``A`` (``asymptotes``), barrier position ``+-inf``;
* closed: ``V -> inf`` (no escape that way), barrier position ``+-inf``.

The escape energy ``barrier_energy`` is the lowest of the barriers' ``V(q_b)`` and the limits;
below it every energy level ``0 <= E < barrier_energy`` carries one periodic orbit around the
well bottom with turning points ``q_minus(E) < 0 < q_plus(E)``.  When it is a limit
(``open_at_infinity``) the orbit at ``barrier_energy`` itself is unbounded, not a separatrix.

Conventions shared by every well (they reproduce eqs (13)-(17), (20) for the quartic):

* ``H0(q, p) = p^2 / 2 + V(q)`` (eq 7 for the quartic); energies ``xi``/``E`` are H0 values.
* the angle ``theta`` advances at ``omega(E) = dE/dJ`` along the free motion ``q' = p,
  p' = -V'(q)``, and ``theta = 0`` where the orbit crosses the well bottom ``q = 0`` with
  ``p > 0``;
* ``q(theta) = sum_k q_k e^{i k theta}``; ``first_harmonic(E)`` is the complex ``q_1``
  (paper eq (12)); for a symmetric well ``q(theta)`` is odd and ``q_1 = -i G`` with ``G`` real
  (eq 20 for the quartic).

Escape criteria (one definition, used by theory, numerics, integrity and plotting):

* energy: ``H0(q, p) > xi_max``, or ``q`` beyond a barrier (there H0 no longer measures the
  well energy; a side open at infinity has its barrier at ``+-inf``: there only ``H0 > xi_max``);
* displacement: ``q < q_minus(xi_max)`` or ``q > q_plus(xi_max)`` (eq (4) for the quartic,
  where ``q_plus = -q_minus = q_max(xi_max)``);
* the unforced safe set of a threshold: ``S0(xi_max) = {H0 < xi_max, q_minus < q < q_plus}``.
"""
from __future__ import annotations

import abc
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np
import numpy.typing as npt
from scipy import optimize

from safebasins.core.checks import BARRIER_RTOL, as_array, reaches, value_repr

if TYPE_CHECKING:  # (compiled imports numba: only the checker needs the name here)
    from safebasins.wells.compiled import WellCode

__all__ = ["Well", "WellLike"]


#: Step costs of the compiled forms relative to the quartic's closed form, rounded up from
#: benchmarks/bench_wells.py (SRKN6b, 1 thread, AMD EPYC AVX-512; docs/numerics.md "Wells"):
#: polynomial codes of degree class 4 measured 1.29, of class 8 2.5-3.07; an arithmetic
#: expression 1.1-1.19; a code calling libm functions (sin, exp, tanh, ...) runs its lanes
#: scalar: pendulum 45-68, Morse 42, sech^2 130 -- the upper bound covers any such well, and a
#: user's Python functions (what they call is unknown).
STEP_COST_POLY4 = 1.5
STEP_COST_POLY8 = 3.5
STEP_COST_ARITHMETIC = 1.5
STEP_COST_TRANSCENDENTAL = 150.0
#: a code calling wells.elementary (vectorised sin, exp, tanh, ...; docs/elementary.md): measured
#: (Intel Cascade Lake, AVX-512 and AVX2) pendulum 14-24, Morse 17-24, sech^2 22-37
STEP_COST_ELEMENTARY = 40.0
#: top of a resonance-manifold panel as a fraction of the escape energy (:attr:`Well.manifold_top`)
MANIFOLD_TOP = 0.9996


class Well(abc.ABC):
    """Abstract potential well; subclasses give V, dV, the barriers and the action-angle data.

    Array arguments broadcast; every method raises ``ValueError`` naming the argument for
    input outside its domain (an energy outside ``[0, barrier_energy)``, a point outside the
    well, NaN).  The element-wise methods take a float or an array and return numpy's float or
    an array of the argument's shape: their results are annotated ``Any`` (numpy's types cannot
    say "the shape of the argument").
    """

    #: short name used in datasets and configs ("quartic", "cubic", "polynomial", ...)
    name: str = "well"
    #: which first harmonic the slow flow uses: the exact one (the quartic can also use the
    #: paper's truncated eq (20): "paper")
    fourier: str = "exact"
    #: upper bound of the time of one integration step of the well's compiled form, in steps of
    #: the quartic's closed form (the cost estimate's unit, safebasins.pipeline.cost); subclasses
    #: set it from their code (the ``STEP_COST_`` constants of this module)
    step_cost: float = 1.0

    # ------------------------------------------------------------------ the potential
    @abc.abstractmethod
    def V(self, q: npt.ArrayLike) -> Any:
        """Potential energy V(q)."""

    @abc.abstractmethod
    def dV(self, q: npt.ArrayLike) -> Any:
        """V'(q) (the restoring force is -V'(q))."""

    @property
    @abc.abstractmethod
    def barriers(self) -> tuple[float, float]:
        """Positions ``(q_left, q_right)`` of the barrier maxima of V on each side of the well
        bottom; ``-inf`` / ``+inf`` on a side where ``V -> inf`` (no escape that way)."""

    @property
    def asymptotes(self) -> tuple[float | None, float | None]:
        """``(left, right)``: on a side without a barrier where V tends to a finite limit as
        ``q -> -inf`` / ``+inf`` (open at infinity), that limit; None on a side with a barrier or
        where ``V -> inf``."""
        return (None, None)

    @property
    def barrier_energy(self) -> float:
        """Escape energy: the lowest of the barriers' ``V(q_b)`` and the finite limits of V at infinity."""
        lo, hi = self.barriers
        vals = [float(self.V(q)) for q in (lo, hi) if np.isfinite(q)] + [a for a in self.asymptotes if a is not None]
        if not vals:
            raise ValueError(f"well {self.name!r} is closed: no barrier and no finite limit of V at infinity "
                             "(V -> inf on both sides): no orbit escapes, there is no escape energy")
        return min(vals)

    @property
    def open_at_infinity(self) -> bool:
        """Whether the escape energy is a limit of V at infinity (then the orbit at
        ``barrier_energy`` is unbounded and thresholds must lie strictly below it)."""
        lims = [a for a in self.asymptotes if a is not None]
        return bool(lims) and min(lims) <= self.barrier_energy

    def H0(self, q: npt.ArrayLike, p: npt.ArrayLike) -> Any:
        """Unforced energy ``p^2 / 2 + V(q)`` (eq 7, untruncated)."""
        q = np.asarray(q, dtype=float)
        p = np.asarray(p, dtype=float)
        return 0.5 * p * p + self.V(q)

    @abc.abstractmethod
    def turning_points(self, E: npt.ArrayLike) -> tuple[Any, Any]:
        """``(q_minus(E), q_plus(E))``: the orbit's turning points, ``q_minus <= 0 <= q_plus``,
        for ``0 <= E <= barrier_energy``."""

    @abc.abstractmethod
    def check_energy(self, name: str, E: npt.ArrayLike, *, allow_separatrix: bool = False) -> Any:
        """``E`` as a float array after checking it is an energy of the well's orbits, ``0 <= E <
        barrier_energy`` (``<=`` with ``allow_separatrix``); a ValueError naming ``name`` otherwise."""

    # ------------------------------------------------------------------ action-angle
    @abc.abstractmethod
    def J(self, E: npt.ArrayLike) -> Any:
        """Action ``J(E) = (1 / 2 pi) oint p dq`` (eq 13 / 19 for the quartic)."""

    @abc.abstractmethod
    def omega(self, E: npt.ArrayLike) -> Any:
        """Frequency ``omega(E) = dE/dJ = 2 pi / period`` (eq 16)."""

    @abc.abstractmethod
    def angle_energy(self, q: npt.ArrayLike, p: npt.ArrayLike) -> tuple[Any, Any]:
        """``(theta, E)`` of phase points inside the well (eqs 7, 14); theta in [0, 2 pi)."""

    @abc.abstractmethod
    def phase_point(self, theta: npt.ArrayLike, E: npt.ArrayLike) -> tuple[Any, Any]:
        """``(q, p)`` at angle theta on the orbit of energy E (eqs 15, 17); inverse of
        :meth:`angle_energy`."""

    @abc.abstractmethod
    def first_harmonic(self, E: npt.ArrayLike) -> Any:
        """Complex first Fourier coefficient ``q_1(E)`` of ``q(theta)`` (eq 12)."""

    # ------------------------------------------------------------------ what the slow flow needs
    # With q_1 = -i A e^{i delta}, q(theta) = 2 A sin(theta + delta) + ... and the averaged
    # forcing term is F A cos(gamma + delta): the first integral (eq 18 generalised) is
    # C(gamma, xi) = xi - Omega J(xi) - F A(xi) cos(gamma + delta(xi)).  The shear
    # gamma -> gamma + delta(xi) is a homeomorphism of the resonance-manifold cylinder that keeps
    # every circle xi = const, so the escape classification, the critical points and the
    # tangencies of the quartic carry over with G -> A and gamma -> gamma + delta(xi).
    @abc.abstractmethod
    def harmonic_amplitude(self, E: npt.ArrayLike) -> Any:
        """``A(E) = |q_1(E)|`` (the quartic's G of eq 20)."""

    @abc.abstractmethod
    def harmonic_amplitude_derivative(self, E: npt.ArrayLike) -> Any:
        """``dA/dE`` for ``0 < E < barrier_energy``."""

    @abc.abstractmethod
    def harmonic_phase(self, E: npt.ArrayLike) -> Any:
        """``arg q_1(E)``, continuous in E (``-pi/2`` for a symmetric well)."""

    def harmonic_shift(self, E: npt.ArrayLike) -> Any:
        """``delta(E) = arg q_1(E) + pi/2``: the slow phase shift of the first harmonic (0 for a
        symmetric well)."""
        return self.harmonic_phase(E) + 0.5 * np.pi

    def in_well(self, q: npt.ArrayLike) -> Any:
        """``q`` strictly between the barriers (everything on a side without a barrier)."""
        lo, hi = self.barriers
        q = np.asarray(q, dtype=float)
        return (q > lo) & (q < hi)

    def check_threshold(self, name: str, xi_max: Any) -> np.ndarray:
        """Energy truncation level of an escape test in ``(0, barrier_energy]``: ``xi_max = E_b`` is
        escape over the barrier, the numerics' and the damped slow flow's test (escape = H0, or the
        slow energy, exceeding it); in ``(0, barrier_energy)`` when the escape energy is a limit of V
        at infinity (the orbit at it is unbounded).  The undamped slow flow needs more:
        :meth:`check_analytic_threshold`."""
        a = as_array(name, xi_max)
        if self.open_at_infinity:
            if ((a <= 0) | (a >= self.barrier_energy)).any():
                raise ValueError(f"{name} must lie in (0, {self.barrier_energy!r}), below the escape energy of the "
                                 f"{self.name} well: it is the limit of V at infinity, where the orbit is unbounded; "
                                 f"got {value_repr(a)}")
            return a
        if ((a <= 0) | (a > self.barrier_energy)).any():
            raise ValueError(f"{name} must lie in (0, {self.barrier_energy!r}] (the barrier energy of the "
                             f"{self.name} well), got {value_repr(a)}")
        return a

    def check_analytic_threshold(self, name: str, xi_max: Any) -> np.ndarray:
        """Truncation level of the undamped slow flow (the level curves of its first integral C):
        :meth:`check_threshold`, and below the escape energy by more than a relative
        ``checks.BARRIER_RTOL`` (closer counts as at it).  That theory needs an orbit at xi_max; at
        the separatrix the period diverges, and F_cr grows like ``log(1 / (E_b - xi_max))`` without
        a limit (the cubic's F_cr at Omega = 0.7: 0.13, 0.17, 0.21, 0.24 at E_b - xi_max = 1e-6,
        1e-10, 1e-13 E_b and one ulp), so a value that close measures the float spacing, not the well."""
        a = self.check_threshold(name, xi_max)
        if reaches(a, self.barrier_energy).any():
            raise ValueError(f"{name} must lie below the barrier energy {self.barrier_energy_text} of the {self.name} "
                             f"well (by more than a relative {BARRIER_RTOL:g}) for the undamped slow flow: it needs an "
                             "orbit at xi_max, and on the separatrix its period diverges; got "
                             f"{value_repr(a)}. Escape over the barrier, xi_max = E_b, is what the numerics (escape "
                             "charts, numeric F_cr) and the damped slow flow test")
        return a

    @property
    def barrier_energy_text(self) -> str:
        """The escape energy as written in messages."""
        return repr(float(self.barrier_energy))

    def unforced_safe(self, q: npt.ArrayLike, p: npt.ArrayLike, xi_max: npt.ArrayLike) -> Any:
        """The unforced safe set of a threshold: ``H0 < xi_max`` inside the well."""
        return (self.H0(q, p) < xi_max) & self.in_well(q)

    # ------------------------------------------------------------------ what the numerics need
    def check_displacement(self, name: str, q_max: Any) -> np.ndarray:
        """Symmetric displacement thresholds ``|q| > q_max``: q_max in (0, nearest barrier]."""
        a = as_array(name, q_max)
        lim = min(-self.barriers[0], self.barriers[1])
        if ((a <= 0) | (a > lim)).any():
            raise ValueError(f"{name} must lie in (0, {lim!r}] (|q| > q_max beyond a barrier of the {self.name} "
                             f"well at {self.barriers}), got {value_repr(a)}")
        return a

    def check_bounds(self, name: str, q_bounds: Any) -> np.ndarray:
        """Displacement bound pairs ``(lo, hi)`` as an (n, 2) float array: lo < 0 < hi, inside the
        barriers (a single pair may be given as (lo, hi))."""
        a = as_array(name, q_bounds)
        if a.size == 0:
            return np.zeros((0, 2))
        if a.ndim == 1:
            a = a[None, :]
        if a.ndim != 2 or a.shape[1] != 2:
            raise ValueError(f"{name} must be pairs (lo, hi): shape (n, 2) or (2,), got shape {a.shape}")
        lo, hi = a[:, 0], a[:, 1]
        if not ((lo < 0) & (hi > 0)).all():
            raise ValueError(f"{name} must satisfy lo < 0 < hi (the well bottom q = 0 inside), got {a.tolist()}")
        ql, qr = self.barriers
        if (lo < ql).any() or (hi > qr).any():
            raise ValueError(f"{name} must lie inside the barriers of the {self.name} well, {ql!r} <= lo and "
                             f"hi <= {qr!r}; got {a.tolist()}")
        return a

    def spec(self) -> dict[str, Any]:
        """The resolved spec that rebuilds this well (:func:`safebasins.wells.from_spec`): its name,
        plus the coefficients or the expression of an unnamed polynomial or expression well."""
        return {"name": self.name}

    def potential_text(self) -> str:
        """``V(q)`` in words for datasets and figures."""
        return f"V(q) of the {self.name} well"

    def barrier_text(self) -> str:
        """Where the escape over a barrier happens, e.g. ``q < -1 or q > 1`` ("" without a finite barrier)."""
        return " or ".join(f"q {op} {b!r}" for op, b in zip(("<", ">"), self.barriers) if np.isfinite(b))

    def energy_criterion(self) -> str:
        """The energy escape criterion in words, naming the well."""
        beyond = self.barrier_text()
        return (f"well {self.name!r}, V(q) = {self.potential_text()}: H0 = p^2/2 + V(q) > xi_max"
                + (f" or {beyond} (beyond a barrier)" if beyond else ""))

    def numerics_attrs(self) -> dict[str, Any]:
        """Attributes a numeric dataset records about its well."""
        return {"well": self.name, "well_potential": self.potential_text(),
                "well_barriers": np.array(self.barriers, dtype=float),
                "well_barrier_energy": float(self.barrier_energy)}

    def ic_window(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """``((q_lo, q_hi), (p_lo, p_hi))``: an initial-condition window holding the whole well, the
        turning points of the escape energy E_b (of 0.99 E_b when they are not finite: a side open
        at infinity) and ``|p| <= 1.5 sqrt(E_b)`` (the quartic: [-1, 1] x [-0.75, 0.75])."""
        E = float(self.barrier_energy)
        try:
            lo, hi = (float(x) for x in self.turning_points(E))
        except ValueError:
            lo = hi = np.inf
        if not (np.isfinite(lo) and np.isfinite(hi)):
            lo, hi = (float(x) for x in self.turning_points(0.99 * E))
        pm = 1.5 * float(np.sqrt(E))
        return (lo, hi), (-pm, pm)

    @property
    def manifold_top(self) -> float:
        """Default top ``xi`` of a resonance-manifold panel ``(gamma, xi)``: ``MANIFOLD_TOP`` E_b, just
        below the separatrix where the slow-flow tables end (the quartic: 0.2499, the paper's Figs 5-9)."""
        return MANIFOLD_TOP * float(self.barrier_energy)

    @property
    def static_escape_force(self) -> float:
        """``F_static``: the largest ``|V'|`` between the well bottom and the turning point of the escape
        energy E_b (a barrier, the closing point of a closed side; on a side open at infinity all of
        it), on the side where that is smaller (the quartic: ``2 / (3 sqrt 3) = 0.385``, at its
        inflection point; the cubic 1/4; the pendulum 1).  A constant force above it has no
        equilibrium on the way: it pushes the particle from rest at the bottom past that turning
        point with ``H0 > E_b >= xi_max`` -- the escape threshold of a forcing slow against the well
        (``Omega -> 0``); resonance lowers it (numerics.bisection's default F bracket)."""
        f = self.__dict__.get("_static_escape_force")
        if f is None:
            f = min(self._largest_force(side) for side in (-1.0, 1.0))
            self.__dict__["_static_escape_force"] = f
        return f

    def _largest_force(self, side: float) -> float:
        """``max |V'|`` between 0 and the turning point of E_b on one side (``side`` -1 or +1): on 2001
        uniform and 2001 geometric points (a long open tail), the largest polished by a bounded scalar
        search between its neighbours."""
        E = float(self.barrier_energy)
        k = 0 if side < 0 else 1
        q_t = float(self.turning_points(E)[k])
        if not np.isfinite(q_t):              # open at infinity: V' decays along the tail
            q_t = float(self.turning_points((1.0 - 1e-9) * E)[k])
        q = np.unique(np.concatenate([np.linspace(0.0, q_t, 2001), q_t * np.geomspace(1e-7, 1.0, 2001)]))
        f = np.abs(np.asarray(self.dV(q), dtype=float))
        i = int(np.argmax(f))
        lo, hi = sorted((q[max(i - 1, 0)], q[min(i + 1, q.size - 1)]))
        res = optimize.minimize_scalar(lambda x: -abs(float(self.dV(np.array([x]))[0])), bounds=(lo, hi),
                                       method="bounded", options={"xatol": 1e-12 * max(abs(q_t), 1.0)})
        return max(float(f[i]), -float(res.fun))

    @property
    def omega_max(self) -> float:
        """The well's largest local frequency ``sqrt(max |V''(q)|)`` over the IC window's q range
        (:meth:`ic_window`), from central differences of V' on 4001 points: the frequency an
        integrator step must resolve (numerics.engine.check_step)."""
        om = self.__dict__.get("_omega_max")
        if om is None:
            (lo, hi), _ = self.ic_window()
            q = np.linspace(lo, hi, 4001)
            h = 1e-5 * max(1.0, hi - lo)
            d2 = (np.asarray(self.dV(q + h), float) - np.asarray(self.dV(q - h), float)) / (2.0 * h)
            om = float(np.sqrt(np.nanmax(np.abs(d2))))
            self.__dict__["_omega_max"] = om
        return om

    @property
    def compiled(self) -> WellCode:
        """The well's one compiled form (:class:`safebasins.wells.compiled.WellCode`: force and
        energy for the CPU and CUDA engines), built on first use and kept."""
        code = self.__dict__.get("_compiled")
        if code is None:
            code = self._compiled_form()
            self.__dict__["_compiled"] = code
        return code

    def _compiled_form(self) -> WellCode:
        raise ValueError(f"the {self.name} well ({type(self).__name__}) has no compiled form for the numerics")


#: any form :func:`safebasins.wells.resolve_well` reads: None (the paper's quartic), a name, a
#: spec mapping (``{"polynomial": [...]}``, ``{"expression": "..."}``) or a :class:`Well`
WellLike: TypeAlias = "Well | str | Mapping[str, Any] | None"
