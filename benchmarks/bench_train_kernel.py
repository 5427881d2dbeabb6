"""Would a compiled kernel take the two-angle sphere-pair table under 1 us a point?

``calibrated-capillary`` evaluates two spheres with two contact angles at 1.3-1.5 us a
point on this project's machines (2.0-2.1 us in this benchmark's slow hour), against the
1 us goal of issue 11; its tensor-train sums
(:func:`wetcontact.reduced_models.calibrated_capillary.train_sum`: small matrix products
through numpy's OpenBLAS, and elementwise sums over the Chebyshev rows, 256 points at a
time) take about 0.8 us of it. ``bench_pair_split`` left "a compiled batched kernel" as the
way under 1 us. This benchmark tries the one compiler the package already installs,
numba (a dependency of py-pde), in place of ``train_sum``, on the points of
``bench_pair_tt`` (1e5, one BLAS thread, alternating rounds, median of 7):

- **numpy (shipped)**: ``train_sum`` as shipped;
- **numba, loops**: every core's contraction as compiled loops, points innermost (so that
  they vectorise), ``V_k[r1, p] += G[r, m, r1] (V_{k-1}[r, p] T_m(x_p))``, one call a
  train, batches of the same 256 points, ``fastmath`` (contraction into fused
  multiply-adds and reassociation allowed: its best case);
- **numba, BLAS products**: the same split as ``train_sum`` (each core one matrix product
  through numba's BLAS binding, the elementwise sums as compiled loops), one call a train,
  without numpy's per-call overhead;
- **C, AVX-512 intrinsics**: a hand-written register-blocked kernel
  (``kernels/train_avx512.c``: one SIMD vector of points at a time through every core, 8
  output ranks in registers, the cores padded with zeros to ranks in multiples of 8),
  compiled here with gcc and loaded with ctypes; left out where gcc or AVX-512 is missing;
- **no train sums (the rest)**: every train returns 0 at once, so its time is that of
  everything else in the evaluation, which no kernel for the trains moves.

The compiled forms take the same rows and cores in the same precision as ``train_sum`` (the
force's train in float32 at the default precision, the rupture distance's in float64), and
their results are checked against it: S_c and force relative changes are reported. The
cores are packed once per table (not timed); the numba compile time (``cache=False``) is
reported separately (the C source compiles in about 0.1 s, outside the timings). For
scale, the rate OpenBLAS reaches alone on matrix products of the trains' shapes is
measured too (:func:`gemm_rates`).

Writes ``benchmarks/results/train_kernel.json`` and ``train_kernel.png``. Run:
``python benchmarks/bench_train_kernel.py`` (under a minute, 15 s of it compiling).
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Any

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numba  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import cost_bars, main_or_chart, median_time, save_chart, write_json  # noqa: E402
from bench_pair_tt import N, points  # noqa: E402

from wetcontact.reduced_models import calibrated_capillary as cc  # noqa: E402

ROUNDS = 7


@numba.njit(cache=False, fastmath=True, error_model="numpy")
def _loops(flat: np.ndarray, offs: np.ndarray, shapes: np.ndarray, order: np.ndarray,
           rows: np.ndarray, roff: np.ndarray, batch: int, out: np.ndarray) -> None:
    """``sum C T...T`` of a tensor train (cores packed in ``flat`` at ``offs``, shapes
    (r0, m, r1) in ``shapes``, axes in ``order``) at the points whose Chebyshev rows are
    stacked in ``rows`` (axis k's from row ``roff[k]``): compiled loops only."""
    n, d = rows.shape[1], shapes.shape[0]
    rmax = 1
    for c in range(d):
        rmax = max(rmax, shapes[c, 0], shapes[c, 2])
    v = np.empty((rmax, batch), dtype=flat.dtype)
    new = np.empty((rmax, batch), dtype=flat.dtype)
    u = np.empty(batch, dtype=flat.dtype)
    for p0 in range(0, n, batch):
        pb = min(batch, n - p0)
        v[0, :pb] = 1.0
        for c in range(d):
            r0, m, r1 = shapes[c, 0], shapes[c, 1], shapes[c, 2]
            tb = roff[order[c]]
            new[:r1, :pb] = 0.0
            for r in range(r0):
                for mm in range(m):
                    for p in range(pb):
                        u[p] = v[r, p] * rows[tb + mm, p0 + p]
                    gb = offs[c] + (r * m + mm) * r1
                    for k in range(r1):
                        g = flat[gb + k]
                        for p in range(pb):
                            new[k, p] += g * u[p]
            v, new = new, v
        out[p0:p0 + pb] = v[0, :pb]


@numba.njit(cache=False, fastmath=True, error_model="numpy")
def _blas(flat: np.ndarray, offs: np.ndarray, shapes: np.ndarray, order: np.ndarray,
          rows: np.ndarray, roff: np.ndarray, batch: int, out: np.ndarray) -> None:
    """As :func:`_loops`, each core's product through BLAS (``train_sum``'s split: the
    product first where r1 <= r0, last otherwise), the elementwise sums compiled."""
    n, d = rows.shape[1], shapes.shape[0]
    for p0 in range(0, n, batch):
        pb = min(batch, n - p0)
        m, r1 = shapes[0, 1], shapes[0, 2]
        t = np.ascontiguousarray(rows[roff[order[0]]:roff[order[0]] + m, p0:p0 + pb])
        v = np.dot(flat[offs[0]:offs[0] + m * r1].reshape(m, r1).T, t)
        for c in range(1, d):
            r0, m, r1 = shapes[c, 0], shapes[c, 1], shapes[c, 2]
            tb = roff[order[c]]
            g = flat[offs[c]:offs[c] + r0 * m * r1]
            if r1 <= r0:
                w = np.dot(g.reshape(r0, m * r1).T, v)
                new = np.zeros((r1, pb), dtype=flat.dtype)
                for mm in range(m):
                    for k in range(r1):
                        for p in range(pb):
                            new[k, p] += w[mm * r1 + k, p] * rows[tb + mm, p0 + p]
                v = new
            else:
                z = np.empty((r0 * m, pb), dtype=flat.dtype)
                for r in range(r0):
                    for mm in range(m):
                        for p in range(pb):
                            z[r * m + mm, p] = v[r, p] * rows[tb + mm, p0 + p]
                v = np.dot(g.reshape(r0 * m, r1).T, z)
        out[p0:p0 + pb] = v[0, :pb]


KERNELS = {"numba, loops": _loops, "numba, BLAS products": _blas}

FLOOR = "no train sums (the rest)"
"""A form whose trains return 0 at once: the cost of everything else in the evaluation
(Chebyshev rows, ridge and onset series, pieces, gap coordinate, exp), which no train
kernel moves; its values are not the table's (no changes reported)."""

C_SOURCE = Path(__file__).resolve().parent / "kernels" / "train_avx512.c"
C_FORM = "C, AVX-512 intrinsics"
C_FLAGS = ("-O3", "-mavx512f", "-mfma", "-fPIC", "-shared")


def c_kernel() -> tuple[Any, str]:
    """:data:`C_SOURCE` compiled with gcc into a temporary folder and loaded (ctypes), and
    the compiler's version; ``(None, why)`` without gcc or AVX-512 (the form is then left
    out of the run)."""
    import ctypes
    import shutil
    import subprocess
    import tempfile

    if shutil.which("gcc") is None:
        return None, "no gcc"
    flags = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").is_file() else ""
    if "avx512f" not in flags:
        return None, "no AVX-512"
    lib = Path(tempfile.mkdtemp()) / "train_avx512.so"
    subprocess.run(["gcc", *C_FLAGS, "-o", str(lib), str(C_SOURCE)], check=True)
    dll = ctypes.CDLL(str(lib))
    ptr = ctypes.c_void_p
    for fn in (dll.train_sum_f32, dll.train_sum_f64):
        fn.argtypes = [ctypes.c_int, *[ptr] * 7, ctypes.c_long, ptr]
        fn.restype = ctypes.c_int
    version = subprocess.run(["gcc", "-dumpfullversion"], capture_output=True,
                             text=True).stdout.strip()
    return dll, f"gcc {version} {' '.join(C_FLAGS[:3])}"


_PADDED: dict[tuple[int, str], tuple[Any, ...]] = {}


def padded(train: dict[str, Any], dtype: Any) -> tuple[Any, ...]:
    """A train's cores in ``dtype`` padded with zeros as :data:`C_SOURCE` needs them (every
    rank but the last a multiple of 8; the values are unchanged), with their shapes, an
    array of pointers to them and the axis order, as int32 / pointer arrays (kept, as
    :func:`packed`)."""
    import ctypes

    key = (id(train), np.dtype(dtype).name)
    if key not in _PADDED:
        cores, prev = [], 1
        for k, g in enumerate(train["cores"]):
            r0, m, r1 = g.shape
            r1p = r1 if k == len(train["cores"]) - 1 else -(-r1 // 8) * 8
            h = np.zeros((prev, m, r1p), dtype=dtype)
            h[:r0, :, :r1] = g
            cores.append(h)
            prev = r1p
        shapes = np.array([g.shape for g in cores], dtype=np.int32)
        ptrs = (ctypes.c_void_p * len(cores))(*[g.ctypes.data for g in cores])
        _PADDED[key] = (cores, *(np.ascontiguousarray(shapes[:, i]) for i in range(3)),
                        ptrs, np.asarray(train["order"], dtype=np.int32))
    return _PADDED[key]


def c_train_sum(dll: Any) -> Any:
    """A drop-in for ``train_sum`` evaluated by the compiled :data:`C_SOURCE`."""
    import ctypes

    def train_sum(train: dict[str, Any], rows: list[np.ndarray]) -> np.ndarray:
        dtype = rows[0].dtype
        cores, r0s, ms, r1s, ptrs, order = padded(train, dtype)
        stacked = np.ascontiguousarray(np.concatenate(rows, axis=0))
        n = stacked.shape[1]
        roff = (np.cumsum([0] + [r.shape[0] for r in rows])[:-1] * n).astype(np.int64)
        out = np.empty(n)
        fn = dll.train_sum_f32 if dtype == np.float32 else dll.train_sum_f64
        if fn(len(cores), r0s.ctypes.data, ms.ctypes.data, r1s.ctypes.data,
              ctypes.cast(ptrs, ctypes.c_void_p), order.ctypes.data, stacked.ctypes.data,
              roff.ctypes.data, n, out.ctypes.data):
            raise ValueError("train_avx512.c: a rank or axis beyond its limits")
        return out
    return train_sum


_PACKED: dict[tuple[int, str], tuple[np.ndarray, ...]] = {}


def packed(train: dict[str, Any], dtype: Any) -> tuple[np.ndarray, ...]:
    """A train's cores flattened in ``dtype`` with their offsets and shapes, and its axis
    order (kept per train and precision, beside the package's table, which stays as it
    is: packing is set-up, not evaluation)."""
    key = (id(train), np.dtype(dtype).name)
    if key not in _PACKED:
        cores = [np.ascontiguousarray(g, dtype=dtype) for g in train["cores"]]
        _PACKED[key] = (np.concatenate([g.ravel() for g in cores]),
                        np.cumsum([0] + [g.size for g in cores])[:-1].astype(np.int64),
                        np.array([g.shape for g in cores], dtype=np.int64),
                        np.asarray(train["order"], dtype=np.int64))
    return _PACKED[key]


def compiled_train_sum(kernel: Any) -> Any:
    """A drop-in for ``train_sum`` evaluated by ``kernel`` in the rows' precision."""
    def train_sum(train: dict[str, Any], rows: list[np.ndarray]) -> np.ndarray:
        flat, offs, shapes, order = packed(train, rows[0].dtype)
        stacked = np.concatenate(rows, axis=0)
        roff = np.cumsum([0] + [r.shape[0] for r in rows])[:-1].astype(np.int64)
        out = np.empty(stacked.shape[1], dtype=rows[0].dtype)
        kernel(flat, offs, shapes, order, stacked, roff, cc.TRAIN_CHUNK, out)
        return out.astype(np.float64)
    return train_sum


GEMM_SHAPES = ((37, 198, 512), (180, 37, 512), (22, 81, 512))
"""(M, K, N) of matrix products like the trains' (``G^T @ Z``: a core against a batch's
rows, 512 points as ``train_sum`` takes them in float32)."""


def gemm_rates() -> dict[str, float]:
    """Multiply-adds per second of OpenBLAS alone on :data:`GEMM_SHAPES`, ``A @ Z`` into a
    preallocated result (the layout ``train_sum`` uses), float32 and float64, median of
    7 timings of 500 products each."""
    rng = np.random.default_rng(0)
    rates = {}
    for dtype in (np.float32, np.float64):
        for m, k, n in GEMM_SHAPES:
            a = rng.standard_normal((m, k)).astype(dtype)
            z = rng.standard_normal((k, n)).astype(dtype)
            out = np.empty((m, n), dtype=dtype)

            def products(a: np.ndarray = a, z: np.ndarray = z, out: np.ndarray = out
                         ) -> None:
                for _ in range(500):
                    np.matmul(a, z, out=out)
            t, _ = median_time(products, repeats=7, warmup=1)
            rates[f"{np.dtype(dtype).name} {m}x{k}x{n}"] = 500 * m * k * n / t
    return rates


def main() -> None:
    v, th, gap, ratio, tw = points()
    shipped = cc.train_sum
    forms = {"numpy (shipped)": shipped,
             **{name: compiled_train_sum(k) for name, k in KERNELS.items()}}
    dll, compiler = c_kernel()
    if dll is not None:
        forms[C_FORM] = c_train_sum(dll)
    print(f"{C_FORM}: {compiler}", flush=True)
    forms[FLOOR] = lambda train, rows: np.zeros(rows[0].shape[1])

    def run(fn: Any) -> tuple[np.ndarray, np.ndarray]:
        cc.kernel.train_sum = fn
        try:
            return cc.force_star("sphere-sphere", v, th, gap, ratio, theta_wall=tw)
        finally:
            cc.kernel.train_sum = shipped

    compile_s, values = {}, {}
    for name, fn in forms.items():  # first call: numba compiles both precisions here
        t0 = time.perf_counter()
        values[name] = run(fn)
        compile_s[name] = time.perf_counter() - t0
    f_ref, sc_ref = values["numpy (shipped)"]
    inside = f_ref > 0
    times: dict[str, list[float]] = {name: [] for name in forms}
    for _ in range(ROUNDS):
        for name, fn in forms.items():
            t0 = time.perf_counter()
            run(fn)
            times[name].append(time.perf_counter() - t0)
    out = {}
    for name, (f, sc) in values.items():
        out[name] = {"s_per_point": float(np.median(times[name]) / N),
                     "first_call_s": compile_s[name]}
        line = f"{name}: {out[name]['s_per_point'] * 1e6:.2f} us a point"
        if name != FLOOR:
            out[name]["max_rel_change_force"] = float(
                np.max(np.abs(f[inside] / f_ref[inside] - 1)))
            out[name]["max_rel_change_rupture"] = float(np.max(np.abs(sc / sc_ref - 1)))
            line += (f" (first call {compile_s[name]:.1f} s), force change "
                     f"{out[name]['max_rel_change_force']:.1e}, S_c change "
                     f"{out[name]['max_rel_change_rupture']:.1e}")
        print(line, flush=True)
    rates = gemm_rates()
    for name, r in rates.items():
        print(f"OpenBLAS alone, {name}: {r / 1e9:.1f} G multiply-adds/s", flush=True)
    result = {"points": N, "rounds": ROUNDS, "numba": numba.__version__, "c": compiler,
              "openblas_multiply_adds_per_s": rates,
              "table": cc.PAIR_TWO_ANGLES, "precision": "mixed (the default)",
              "points_seed": "bench_pair_tt.points", "forms": out,
              "date": time.strftime("%Y-%m-%d")}
    write_json("train_kernel", result)
    chart(result)


def chart(result: dict[str, Any]) -> None:
    fig, ax, names, cost = cost_bars(result["forms"], (8.5, 3.6))
    for y, c in enumerate(cost):
        ax.text(c, y, f" {c:.2f} us ({c / cost[0]:.2f}x)", va="center", fontsize=9)
    ax.axvline(1.0, color="k", ls="--", lw=1, zorder=0)
    ax.set_ylim(len(names) - 0.5, -1.0)  # room above the bars for the goal's label
    ax.text(1.0, -0.75, " 1 us goal", fontsize=9, va="center")
    ax.set_xlim(0, max(cost) * 1.35)
    ax.set_xlabel("cost a point, force and S_c (us, one BLAS thread, 1e5 points)")
    ax.set_title("calibrated-capillary, two spheres with two contact angles:\n"
                 "the tensor-train sums in numpy, compiled by numba, or in C (AVX-512)",
                 fontsize=10)
    save_chart(fig, "train_kernel")


if __name__ == "__main__":
    main_or_chart("train_kernel", main, chart)
