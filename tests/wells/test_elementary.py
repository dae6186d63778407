"""wells.elementary: error in ulps against mpmath (samples over each function's whole domain plus
the hard points: huge sin/cos arguments, subnormals, the overflow edges) within the stated bounds
(elementary.ULP_BOUNDS), the special values of IEEE 754 / C99 Annex F, and the same bits from the
CPU compilation, the plain Python source and the CUDA compilation under numba's simulator (NaN
payloads aside; a
subprocess: the simulator must be on before numba.cuda is imported).  The dense sweep whose maxima
docs/elementary.md states is benchmarks/bench_elementary.py; here 2000 samples per function."""
from __future__ import annotations

import json
import math
import sys
from typing import Any

import numpy as np
import pytest
from numba import cuda, njit

from safebasins.wells import elementary
from tests.wells import elementary_reference as ref
from tests.cuda_simulator import pin_to_one_cpu, run_simulator

N_SAMPLES = 2000
#: samples per function for the simulator (Python speed)
N_SIMULATOR = 200
INF, NAN = math.inf, math.nan

# (function, arguments, expected): C99 Annex F (F.10) and IEEE 754 for the square root
SPECIAL = [
    ("sin", (0.0,), 0.0), ("sin", (-0.0,), -0.0), ("sin", (INF,), NAN), ("sin", (-INF,), NAN), ("sin", (NAN,), NAN),
    ("cos", (0.0,), 1.0), ("cos", (-0.0,), 1.0), ("cos", (INF,), NAN), ("cos", (NAN,), NAN),
    ("tan", (0.0,), 0.0), ("tan", (-0.0,), -0.0), ("tan", (INF,), NAN), ("tan", (NAN,), NAN),
    ("exp", (0.0,), 1.0), ("exp", (-0.0,), 1.0), ("exp", (INF,), INF), ("exp", (-INF,), 0.0), ("exp", (NAN,), NAN),
    ("exp", (710.0,), INF), ("exp", (-746.0,), 0.0), ("exp", (1e308,), INF), ("exp", (-1e308,), 0.0),
    ("expm1", (0.0,), 0.0), ("expm1", (-0.0,), -0.0), ("expm1", (INF,), INF), ("expm1", (-INF,), -1.0),
    ("expm1", (NAN,), NAN), ("expm1", (710.0,), INF), ("expm1", (-1e308,), -1.0),
    ("log", (0.0,), -INF), ("log", (-0.0,), -INF), ("log", (1.0,), 0.0), ("log", (-1.0,), NAN),
    ("log", (-INF,), NAN), ("log", (INF,), INF), ("log", (NAN,), NAN), ("log", (-5e-324,), NAN),
    ("log1p", (0.0,), 0.0), ("log1p", (-0.0,), -0.0), ("log1p", (-1.0,), -INF), ("log1p", (-2.0,), NAN),
    ("log1p", (INF,), INF), ("log1p", (-INF,), NAN), ("log1p", (NAN,), NAN),
    ("tanh", (0.0,), 0.0), ("tanh", (-0.0,), -0.0), ("tanh", (INF,), 1.0), ("tanh", (-INF,), -1.0),
    ("tanh", (NAN,), NAN),
    ("cosh", (0.0,), 1.0), ("cosh", (-0.0,), 1.0), ("cosh", (INF,), INF), ("cosh", (-INF,), INF),
    ("cosh", (NAN,), NAN), ("cosh", (711.0,), INF),
    ("sinh", (0.0,), 0.0), ("sinh", (-0.0,), -0.0), ("sinh", (INF,), INF), ("sinh", (-INF,), -INF),
    ("sinh", (NAN,), NAN), ("sinh", (-711.0,), -INF),
    ("sqrt", (0.0,), 0.0), ("sqrt", (-0.0,), -0.0), ("sqrt", (INF,), INF), ("sqrt", (-1.0,), NAN),
    ("sqrt", (-INF,), NAN), ("sqrt", (NAN,), NAN),
    ("pow", (0.0, -3.0), INF), ("pow", (-0.0, -3.0), -INF), ("pow", (0.0, -2.0), INF), ("pow", (-0.0, -0.5), INF),
    ("pow", (-0.0, -INF), INF), ("pow", (0.0, 3.0), 0.0), ("pow", (-0.0, 3.0), -0.0), ("pow", (-0.0, 2.0), 0.0),
    ("pow", (-0.0, 0.5), 0.0), ("pow", (-1.0, INF), 1.0), ("pow", (-1.0, -INF), 1.0), ("pow", (1.0, NAN), 1.0),
    ("pow", (NAN, 0.0), 1.0), ("pow", (NAN, -0.0), 1.0), ("pow", (-2.0, 0.5), NAN), ("pow", (0.5, -INF), INF),
    ("pow", (2.0, -INF), 0.0), ("pow", (0.5, INF), 0.0), ("pow", (2.0, INF), INF), ("pow", (-INF, -3.0), -0.0),
    ("pow", (-INF, -2.0), 0.0), ("pow", (-INF, 3.0), -INF), ("pow", (-INF, 2.0), INF), ("pow", (INF, -1.0), 0.0),
    ("pow", (INF, 0.5), INF), ("pow", (NAN, 1.0), NAN), ("pow", (2.0, NAN), NAN), ("pow", (-8.0, 1.0 / 3.0), NAN),
    ("pow", (2.0, 1024.0), INF), ("pow", (2.0, -1075.0), 0.0), ("pow", (-2.0, 1025.0), -INF),
    ("pow", (-2.0, 3.0), -8.0), ("pow", (-2.0, 2.0), 4.0),
    ("powi", (0.0, -3), INF), ("powi", (-0.0, -3), -INF), ("powi", (-0.0, 3), -0.0), ("powi", (-0.0, 2), 0.0),
    ("powi", (NAN, 0), 1.0), ("powi", (INF, -1), 0.0), ("powi", (-INF, 3), -INF), ("powi", (-INF, -3), -0.0),
    ("powi", (NAN, 3), NAN), ("powi", (2.0, 1024), INF), ("powi", (-2.0, 1025), -INF), ("powi", (2.0, -1080), 0.0),
]


def _same(got: float, want: float) -> bool:
    """Equal as IEEE values including the sign of zero; NaN matches NaN."""
    if math.isnan(want):
        return math.isnan(got)
    return got == want and math.copysign(1.0, got) == math.copysign(1.0, want)


def _special_arrays(name: str) -> tuple[np.ndarray, np.ndarray | None, list[float]]:
    rows = [(a, w) for f, a, w in SPECIAL if f == name]
    x = np.array([a[0] for a, _ in rows])
    y = np.array([float(a[1]) for a, _ in rows]) if len(rows[0][0]) == 2 else None
    return x, y, [w for _, w in rows]


@pytest.mark.parametrize("name", ref.CHECKED)
def test_error_in_ulps_within_the_stated_bound(name: str) -> None:
    """Samples over the whole domain and the hard points, CPU compilation against mpmath."""
    bound = elementary.ULP_BOUNDS[name]
    for x, y in (ref.samples(name, N_SAMPLES), ref.hard_points(name)):
        worst, at, at_y = ref.max_ulp(name, x, y, ref.cpu_values(name, x, y))
        assert worst <= bound, f"{name}({at}{'' if at_y is None else ', ' + repr(at_y)}): {worst:.3f} ulp > {bound}"


def test_the_bound_is_tight_enough_to_fail() -> None:
    """The ulp measure sees a one-ulp error: the next double after the correctly rounded sin is
    more than the bound away from mpmath's value."""
    x = 0.7
    r = ref.reference("sin", x)
    assert ref.ulp_error(float(r), r) <= 0.5
    assert ref.ulp_error(math.nextafter(float(r), 1.0), r) > elementary.ULP_BOUNDS["sin"]


@pytest.mark.parametrize("name", sorted({f for f, _, _ in SPECIAL}))
def test_special_values(name: str) -> None:
    x, y, want = _special_arrays(name)
    got_cpu = ref.cpu_values(name, x, y)
    for i, w in enumerate(want):
        args = (float(x[i]),) if y is None else (float(x[i]), float(y[i]) if name == "pow" else int(y[i]))
        got_py = getattr(elementary, name)(*args)
        assert _same(float(got_cpu[i]), w), (name, args, float(got_cpu[i]), w)
        assert _same(got_py, w), (name, args, got_py, w)


def test_sincos_is_sin_and_cos() -> None:
    x, _ = ref.samples("sin", N_SAMPLES)
    x = np.concatenate([x, ref.hard_points("sin")[0], [0.0, -0.0, INF, NAN]])
    s, c = np.empty_like(x), np.empty_like(x)
    f = elementary.cpu().sincos
    for i in range(x.size):
        s[i], c[i] = f(x[i])
    assert np.array_equal(s.view(np.int64), ref.cpu_values("sin", x).view(np.int64))
    assert np.array_equal(c.view(np.int64), ref.cpu_values("cos", x).view(np.int64))


def test_exp_expm1_is_exp_and_expm1() -> None:
    """The pair from one reduction has exp's and expm1's bits (compiled and as Python source)."""
    x, _ = ref.samples("expm1", N_SAMPLES)
    hx, _ = ref.hard_points("exp")
    x = np.concatenate([x, hx, ref.samples("exp", N_SAMPLES)[0], [0.0, -0.0, INF, -INF, NAN, -38.0, -37.9, 41.0,
                                                                   42.0, 1e-17, -1e-17, 5e-324]])
    e, m = np.empty_like(x), np.empty_like(x)
    f = elementary.cpu().exp_expm1
    for i in range(x.size):
        e[i], m[i] = f(x[i])
    want_e, want_m = ref.cpu_values("exp", x), ref.cpu_values("expm1", x)
    assert np.array_equal(e, want_e, equal_nan=True) and np.array_equal(m, want_m, equal_nan=True)
    finite = ~np.isnan(x)
    assert np.array_equal(e[finite].view(np.int64), want_e[finite].view(np.int64))
    assert np.array_equal(m[finite].view(np.int64), want_m[finite].view(np.int64))
    py = [elementary.exp_expm1(float(v)) for v in x[finite][::7]]
    assert np.array_equal(np.array(py).view(np.int64), np.stack([e[finite][::7], m[finite][::7]], 1).view(np.int64))


def _simulator_cases() -> dict[str, dict[str, list[float]]]:
    cases = {}
    for name in ref.CHECKED:
        x, y = ref.samples(name, N_SIMULATOR, seed=7)
        hx, hy = ref.hard_points(name)
        x = np.concatenate([x, hx])
        if y is not None and hy is not None:
            y = np.concatenate([y, hy])
        if any(f == name for f, _, _ in SPECIAL):
            sx, sy, _ = _special_arrays(name)
            x = np.concatenate([x, sx])
            y = None if y is None or sy is None else np.concatenate([y, sy])
        cases[name] = {"x": x.tolist()} | ({} if y is None else {"y": y.tolist()})
    return cases


def _simulator_child() -> None:
    """In the subprocess (NUMBA_ENABLE_CUDASIM=1): the CUDA compilation's values, as bit patterns,
    computed by a kernel (one thread per argument)."""
    cases = json.load(sys.stdin)
    dev = elementary.cuda_device()
    out = {}
    for name, c in cases.items():
        f = getattr(dev, name)
        x = np.array(c["x"])
        res = np.empty_like(x)
        if "y" in c:
            y = np.array(c["y"]) if name == "pow" else np.array(c["y"]).astype(np.int64)

            @cuda.jit  # type: ignore[untyped-decorator]  # numba's decorators are unannotated
            def k2(x: np.ndarray, y: np.ndarray, res: np.ndarray, f: Any = f) -> None:
                i = cuda.grid(1)  # type: ignore[attr-defined]  # numba.cuda's attributes are set at import
                if i < x.size:
                    res[i] = f(x[i], y[i])
            k2[(x.size + 31) // 32, 32](x, y, res)
        else:
            @cuda.jit  # type: ignore[untyped-decorator]  # as k2
            def k1(x: np.ndarray, res: np.ndarray, f: Any = f) -> None:
                i = cuda.grid(1)  # type: ignore[attr-defined]  # numba.cuda's attributes are set at import
                if i < x.size:
                    res[i] = f(x[i])
            k1[(x.size + 31) // 32, 32](x, res)
        out[name] = res.view(np.int64).tolist()
    print(json.dumps(out))


def test_cpu_python_and_cuda_simulator_give_the_same_bits() -> None:
    cases = _simulator_cases()
    r = run_simulator(__file__, json.dumps(cases), timeout=300)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    gpu = json.loads(r.stdout.strip().splitlines()[-1])
    assert sorted(gpu) == sorted(cases)
    for name, c in cases.items():
        x = np.array(c["x"])
        y = np.array(c["y"]) if "y" in c else None
        cpu = ref.cpu_values(name, x, y).view(np.int64)
        f = getattr(elementary, name)
        py = np.array([f(float(a)) if y is None else f(float(a), float(b) if name == "pow" else int(b))
                       for a, b in zip(x, x if y is None else y)]).view(np.int64)
        assert _same_bits(np.array(gpu[name], np.int64), cpu), name
        assert _same_bits(py, cpu), name


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal bit patterns, any NaN equal to any NaN (IEEE 754 leaves a NaN's sign and payload to
    the hardware: x86 returns -NaN for sqrt(-1))."""
    na, nb = np.isnan(a.view(float)), np.isnan(b.view(float))
    return bool(np.array_equal(na, nb) and np.array_equal(a[~na], b[~nb]))


if __name__ == "__main__":
    pin_to_one_cpu()
    _simulator_child()


#: the rare paths a vectorised loop calls out of line (masked: only the lanes that need them), by function
COLD_PATHS = {"sin": ("_sin_huge",), "cos": ("_cos_huge",), "exp": ("_exp_tiny",), "pow": ("_pow_tiny",)}


@pytest.mark.parametrize("name", sorted(COLD_PATHS))
def test_rare_paths_are_masked_calls_out_of_the_lanes(name: str) -> None:
    """A loop over the function vectorises and reaches its rare paths (huge sin/cos arguments,
    results near the subnormal range) through their masked vector variants, not inline (inline,
    exp's subnormal rounding doubled its cost on AVX2); lanes on both paths in one vector give
    the bits of the Python source, argument by argument."""
    f = getattr(elementary.cpu(), name)
    rng = np.random.default_rng(3)
    if name == "pow":
        tiny = rng.uniform(1e-3, 0.99, 64)
        x = np.concatenate([tiny, rng.uniform(0.5, 20.0, 64)])
        y = np.concatenate([rng.uniform(-744.0, -709.0, 64) / np.log(tiny), rng.uniform(-3.0, 3.0, 64)])
        order = rng.permutation(x.size)                  # y log x near -745..-709 (subnormal) and normal
        x, y = x[order], y[order]

        @njit
        def loop2(x: np.ndarray, y: np.ndarray, out: np.ndarray) -> None:
            for i in range(x.size):
                out[i] = f(x[i], y[i])
        loop, args = loop2, (x, y)
    else:
        rare = rng.uniform(2.0 ** 31, 1e300, 64) if name in ("sin", "cos") else rng.uniform(-745.0, -708.0, 64)
        x = np.concatenate([rare, rng.uniform(-20.0, 20.0, 64)])
        rng.shuffle(x)
        @njit
        def loop1(x: np.ndarray, out: np.ndarray) -> None:
            for i in range(x.size):
                out[i] = f(x[i])
        loop = loop1
        args = (x,)
    out = np.empty(x.size)
    loop(*args, out)
    ir = loop.inspect_llvm(loop.signatures[0])
    assert "vector.body" in ir
    for path in COLD_PATHS[name]:
        assert f"@safebasins_cold_{path}_v" in ir, f"{path} is not a masked vector call"
    py = getattr(elementary, name)
    want = np.array([py(*(float(a[i]) for a in args)) for i in range(x.size)])
    assert np.array_equal(out.view(np.int64), want.view(np.int64))
    if name in ("exp", "pow"):
        assert np.any((out != 0.0) & (np.abs(out) < 2.2250738585072014e-308)), "no lane took the subnormal path"
