r"""Yade's capillary files ``M(r=1)`` ... ``M(r=10)`` for any contact angle.

Yade's ``Law2_ScGeom_CapillaryPhys_Capillarity`` interpolates (linearly, in distance then in
suction, then in radius ratio) ten tables of suction-controlled bridges between two spheres,
one per radius ratio ``r = R2/R1 >= 1`` in 1, 1.1, 1.25, 1.5, 1.75, 2, 3, 4, 5, 10, read from
the working directory as ``"M(r=" + r + ")" + suffCapFiles``. Layout (Yade's ``Tableau`` and
``TableauD`` readers; ``writesCapFile.m`` in Yade's ``examples/capillaryLaplaceYoung``)::

    r
    n_D
    n_rows 0 0 0 0 0 0 0        (rest of the line ignored)
    D* u* V* F* delta1 delta2 nn11* nn33*     (n_rows rows, u* increasing)
    ...                          (n_D such blocks, D* increasing; each block one D*)

with the larger radius R2 as unit: ``D* = D/R2``, ``u* = u R2/sigma`` (u = -dp the
suction), ``V* = V/R2^3``, ``F* = F/(2 pi sigma R2)`` (attraction > 0), ``delta1``,
``delta2`` the half-filling angles on the small and the large sphere (degrees),
``nn11* = pi \int r sin^2(psi) ds / R2^2`` and ``nn33* = 2 pi \int r cos^2(psi) ds / R2^2``
(``2 nn11 + nn33`` is the area; Duriez & Wan 2017). Blocks must not be empty.

Grids as Yade's generator: ``n_distances`` distances from 0 to the largest rupture distance
(at zero suction) times ``1 - FOLD_MARGIN``; ``u* = 0`` then ``n_suctions - 1`` values
geometric from 0.002 to the suction whose bridge at contact has a 0.7 deg mean filling
angle. Rows are stable bridges from :class:`wetcontact.solver.meniscus.SuctionBridges`,
filling angles on the small sphere capped at ``min(90 deg - theta, 70 deg)``; a distance
no grid suction reaches takes bisected suctions between its neighbours
(:func:`_fill_holes`). Near the fold every column varies like ``sqrt(S_fold - D)``, so rows
whose secant ``|d ln V / dD*|`` exceeds ``POLISH_SLOPE``, the rows of a branch's last
interval, and rows of small suction elasticity (below ``POLISH_ELASTICITY``) are re-solved
at fixed (D*, u*) on ``POLISH_ELEMENTS`` elements.

Accuracy: every row within 1e-6 of an independent ODE shooting (largest 4.4e-7, in nn11*;
``tests/export/yade_rows.py``, ``benchmarks/bench_export_yade.py``); Yade reading the files
within 5.8e-4 of ``meniscus`` off the grid. Commands, grids and checks: the guide's pages
*Export to DEM codes* and *Verification*.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import shutil
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from wetcontact.errors import InputError, SolverError
from wetcontact.fileio import atomic_write_text, fsync_dir
from wetcontact.solver.meniscus import SuctionBridges

RATIOS: tuple[float, ...] = (1.0, 1.1, 1.25, 1.5, 1.75, 2.0, 3.0, 4.0, 5.0, 10.0)
COLUMNS = ("D*", "u*", "V*", "F*", "delta1_deg", "delta2_deg", "nn11*", "nn33*")
U_FIRST = 0.002          # first positive u* (Yade's generator, after Scholtes 2008)
FILLING_AT_MAX_U = 0.7   # deg: mean filling angle at contact at the largest suction
DEFAULT_ELEMENTS = 32    # P2 elements: rows within 1e-7 of the 128-element solve (test)
POLISH_ELEMENTS = 256    # rows re-solved on the finer mesh: next to their fold,
POLISH_SLOPE = 10.0      # ... those where |d ln V / dD*| > 10 (at fixed u*), or in the
                         # branch's last interval before the fold
POLISH_ELASTICITY = 0.6  # ... and where max(u*, 0.002) |d ln V / du*| < 0.6 (small u*)
FOLD_MARGIN = 1e-4       # no row within 1e-4 (relative) of its fold (see the module notes)
CAP_AT_MAX_U = 0.9       # contact angle near 90 deg: the largest suction's contact bridge
                         # fills 0.9 of the cap on the small sphere (its start is at contact)
U_MIN_TOP = 1.0          # ... and the largest suction is at least 1 (the 0.7 deg bridge at
                         # contact turns convex, u* < 0, above about 88.9 deg)
FILL_LEVELS = 6          # a hole in the grid: up to 2**6 - 1 intermediate suctions
FILL_ROWS = 2            # ... until this many reach each of its distances


def file_name(ratio: float, suffix: str = "") -> str:
    """Yade's file name for one radius ratio: ``M(r=1.25)`` + suffix."""
    return f"M(r={ratio:g}){suffix}"


def default_suffix(contact_angle_deg: float) -> str:
    """The ``suffCapFiles`` tag of a contact angle, e.g. ``_theta20``."""
    return f"_theta{contact_angle_deg:g}"


@dataclass(frozen=True)
class CapillaryTable:
    """One Yade capillary file's content.

    Attributes
    ----------
    ratio, contact_angle
        r = R2/R1 (>= 1) and theta (rad, the same on both spheres).
    distances, suctions
        The D* grid (increasing, from 0) and the u* grid (increasing, from 0).
    rows
        (n, 8) array of :data:`COLUMNS`, sorted by D* then u*.
    rupture
        D* of the fold (largest gap) at each suction.
    solves, wall_time_s
        Newton solves spent and the wall time of the table.
    polished
        Rows re-solved on ``POLISH_ELEMENTS`` elements (next to their fold, small suction).
    intermediate
        Suctions between grid suctions whose rows fill the blocks that no grid suction
        reaches (a coarse suction grid; :func:`_fill_holes`).
    """

    ratio: float
    contact_angle: float
    distances: np.ndarray
    suctions: np.ndarray
    rows: np.ndarray
    rupture: np.ndarray
    solves: int
    wall_time_s: float
    polished: int = 0
    intermediate: int = 0

    def blocks(self) -> list[np.ndarray]:
        """Rows grouped by distance, as Yade reads them."""
        return [self.rows[self.rows[:, 0] == D] for D in self.distances]


def _row(b: SuctionBridges, x: np.ndarray, D: float, u: float) -> list[float]:
    """One file row from a dimensionless solution (unit R2 = 1) solved at gap D, suction u
    (written exactly: the closings hold them to round-off)."""
    # the attraction at the contact line on the small sphere, over 2 pi sigma R2
    vol, f, c1, c2, nn11, nn33 = b.quantities(x)
    return [D, u, vol, f, math.degrees(c1), math.degrees(c2), nn11, nn33]


def _polish(bc: SuctionBridges, bf: SuctionBridges, x: np.ndarray, u: float,
            S: float) -> np.ndarray:
    """The bridge at suction u and gap S on the fine discretisation ``bf``, from the coarse
    solution x of ``bc``."""
    xf = bf.solve(bf.transfer(bc, x), S, suction=u, maxit=20)
    if xf is None or abs(bf.filling(xf) - bc.filling(x)) > 1e-4:
        raise SolverError(f"yade export: the {bf.n_elements}-element re-solve failed at "
                          f"D* = {S:.6g}, u* = {u:.6g}")
    return xf


def _flat_in_suction(rows: np.ndarray) -> np.ndarray:
    """Rows whose volume barely depends on the suction at their distance:
    ``max(u*, U_FIRST) |d ln V / du*| < POLISH_ELASTICITY`` (the derivative along the D
    block by finite differences; blocks of one row count as flat)."""
    flat = np.zeros(rows.shape[0], bool)
    for D in np.unique(rows[:, 0]):
        idx = np.flatnonzero(rows[:, 0] == D)
        idx = idx[np.argsort(rows[idx, 1])]
        if idx.size < 2:
            flat[idx] = True
            continue
        u = rows[idx, 1]
        slope = np.gradient(np.log(rows[idx, 2]), u)
        flat[idx] = np.maximum(u, U_FIRST) * np.abs(slope) < POLISH_ELASTICITY
    return flat


def _largest_suction(b: SuctionBridges) -> tuple[float, np.ndarray]:
    """u* at which the contact bridge has mean filling angle FILLING_AT_MAX_U; its solution.

    Near a contact angle of 90 deg that bridge is inadmissible for the grid, and the bridge
    at contact is taken smaller (higher suction) instead: where its suction is below
    ``U_MIN_TOP`` (above about 88.9 deg the 0.7 deg bridge at contact turns convex, u* < 0),
    the bridge at contact at ``U_MIN_TOP``; then, where its filling angle on the small
    sphere passes the cap ``c1_max`` (above about 88.7 deg; no grid suction would have a
    bridge at contact), the one with ``CAP_AT_MAX_U * c1_max`` there.
    """
    target = 2.0 * math.radians(FILLING_AT_MAX_U)
    c1_max = b.max_filling
    c1 = target / (1.0 + 1.0 / b.ratio)     # equal neck radii: R1 c1 = R2 c2 (R2 = 1)
    x0 = b.guess(0.0, min(c1, CAP_AT_MAX_U * c1_max))
    if x0 is None:
        raise SolverError("yade export: no toroidal guess for the smallest bridge")
    x = b.solve(x0, 0.0, filling_sum=target, maxit=30)
    if x is not None and b.suction(x) < U_MIN_TOP:
        x = b.solve(x, 0.0, suction=U_MIN_TOP, maxit=30)
    if x is not None and b.filling(x) > c1_max:
        x = b.solve(x, 0.0, filling=CAP_AT_MAX_U * c1_max, maxit=30)
    if x is None or not 0.0 < b.filling(x) <= c1_max or b.suction(x) < U_MIN_TOP:
        raise SolverError("yade export: the smallest bridge at contact did not converge")
    return b.suction(x), x


def _start(b: SuctionBridges, u_prev: float, x_prev: np.ndarray, u: float,
           depth: int = 0) -> np.ndarray | None:
    """Branch start at suction u continued from the start at u_prev (halving the step in
    log u, or linearly towards 0, when Newton does not reach it in one step)."""
    x = b.start(u, x_prev)
    if x is not None or depth > 30:
        return x
    mid = math.sqrt(u * u_prev) if u > 0 else (0.5 * u_prev if u_prev > 1e-3 else 0.0)
    if mid == u:
        return None
    xm = _start(b, u_prev, x_prev, mid, depth + 1)
    return None if xm is None else _start(b, mid, xm, u, depth + 1)


def _reaches(br, distances: np.ndarray) -> np.ndarray:
    """Mask of the distances at which a suction branch has an admitted stable bridge: from
    its start (contact, or the filling-angle cap) to ``1 - FOLD_MARGIN`` times its fold."""
    return (distances >= br.S_start - 1e-13) & (distances <= br.S_fold * (1.0 - FOLD_MARGIN))


def _between(u_lo: float, u_hi: float, t: float) -> float:
    """The suction a fraction ``t`` of the way from ``u_lo`` to ``u_hi``: geometric, as the
    grid (linear from ``u_lo = 0``)."""
    return u_lo + t * (u_hi - u_lo) if u_lo == 0.0 else u_lo * (u_hi / u_lo) ** t


def _fill_holes(b: SuctionBridges, suctions: np.ndarray, branches: list, starts: list,
                holes: np.ndarray) -> tuple[list, int]:
    """Rows for the grid distances that no grid suction reaches.

    Both ends of a suction's branch, its start (contact, or the filling-angle cap) and its
    fold, fall as the suction rises. On a coarse suction grid a distance can lie above the
    fold of a suction ``u_hi`` and below the start of the next lower one ``u_lo``: no grid
    suction has an admitted bridge there, and an empty block would crash Yade's reader.
    Such a block takes intermediate suctions ``u_lo (u_hi/u_lo)^(j/2^L)`` (linear from
    ``u_lo = 0``), each branch continued from the start at the next higher one, ``L``
    growing up to ``FILL_LEVELS`` until ``FILL_ROWS`` of them reach each of its distances
    (at least one at the last level).

    Returns the ``(u, branch, distances)`` triples of the intermediate suctions that reach
    a hole, and the Newton solves spent.
    """
    plan, solves = [], 0
    todo = np.asarray(holes, float)
    top = 2 ** FILL_LEVELS
    for i in range(len(suctions) - 1):
        lo, hi = branches[i], branches[i + 1]
        here = todo[(todo < lo.S_start - 1e-13) & (todo > hi.S_fold * (1.0 - FOLD_MARGIN))]
        if here.size == 0:
            continue
        todo = np.setdiff1d(todo, here)
        u_lo, u_hi = float(suctions[i]), float(suctions[i + 1])
        done: dict[int, tuple] = {top: (u_hi, starts[i + 1], None)}
        for level in range(1, FILL_LEVELS + 1):
            step = top >> level
            for j in range(top - step, 0, -step):       # decreasing suction
                if j in done:
                    continue
                u_prev, x_prev, _ = done[min(k for k in done if k > j)]
                u = _between(u_lo, u_hi, j / top)
                x = _start(b, u_prev, x_prev, u)
                if x is None:
                    raise SolverError(f"yade export: no stable bridge at u* = {u:.6g} (between "
                                      f"the grid's {u_lo:.6g} and {u_hi:.6g})")
                br = b.branch(u, x)
                solves += br.solves + 1
                done[j] = (u, x, br)
            counts = sum(_reaches(br, here).astype(int)
                         for _, _, br in done.values() if br is not None)
            if np.all(counts >= FILL_ROWS):
                break
        if np.any(counts < 1):
            raise SolverError(f"yade export: no bridge at D* = {here[counts < 1][0]:.6g} at "
                              f"{top - 1} suctions between {u_lo:.6g} and {u_hi:.6g}")
        for j in sorted(done):
            u, _, br = done[j]
            if br is not None and np.any(sel := _reaches(br, here)):
                plan.append((u, br, here[sel]))
    if todo.size:
        raise SolverError(f"yade export: no bridge at D* = {todo[0]:.6g}: no grid suction's "
                          "branch reaches it")
    return plan, solves


def capillary_table(ratio: float, contact_angle: float, n_suctions: int = 350,
                    n_distances: int = 80, n_elements: int = DEFAULT_ELEMENTS,
                    max_suction: float | None = None) -> CapillaryTable:
    """The suction-controlled bridges of one radius ratio on Yade's (D*, u*) grid.

    Suctions are taken in decreasing order so that each branch start (contact, or the
    largest admitted filling angle) is continued from the previous one; along each suction
    the gap is followed from its start to the fold (:meth:`SuctionBridges.branch`), and the
    rows are the stable bridges at the grid distances it reaches
    (:meth:`SuctionBridges.at_gaps`). A grid
    distance that no grid suction reaches takes rows at intermediate suctions
    (:func:`_fill_holes`), so that no block is empty.
    ``max_suction`` (u*) lowers the top of the suction grid (reduced tables for tests).
    """
    if not (math.isfinite(ratio) and ratio >= 1.0):
        raise InputError(f"yade export: radius ratio = {ratio!r}; allowed: >= 1")
    if not 0.0 <= contact_angle < math.radians(89.0):
        raise InputError(f"yade export: contact angle = {math.degrees(contact_angle):.6g} "
                         "deg; allowed: [0, 89) deg (Yade's files are for pendular bridges "
                         "with filling angle + contact angle <= 90 deg)")
    if n_suctions < 3 or n_distances < 2:
        raise InputError(f"yade export: suctions = {n_suctions}, distances = {n_distances}; "
                         "allowed: >= 3 and >= 2")
    t0 = time.perf_counter()
    b = SuctionBridges(ratio, contact_angle, int(n_elements))
    u_max, x = _largest_suction(b)
    if max_suction is not None:
        if not U_FIRST < max_suction < u_max:
            raise InputError(f"yade export: max_suction = {max_suction!r}; allowed: "
                             f"({U_FIRST}, {u_max:.6g})")
        u_max = float(max_suction)
    suctions = np.concatenate([[0.0], np.geomspace(U_FIRST, u_max, n_suctions - 1)])
    branches, starts = [], []
    solves = 1
    u_prev = u_max
    for u in suctions[::-1]:
        start = _start(b, u_prev, x, float(u))
        if start is None:
            raise SolverError(f"yade export: no stable bridge at u* = {u:.6g}, r = {ratio:g}")
        br = b.branch(float(u), start)
        branches.append(br)
        starts.append(start)
        solves += br.solves + 1
        x, u_prev = start, float(u)
    branches, starts = branches[::-1], starts[::-1]
    rupture = np.array([br.S_fold for br in branches])
    D_max = float(np.max(rupture)) * (1.0 - FOLD_MARGIN)
    distances = np.linspace(0.0, D_max, n_distances)
    plan = [(float(u), br, distances[_reaches(br, distances)])
            for u, br in zip(suctions, branches, strict=True)]
    covered = np.zeros(distances.size, bool)
    for _, br, _ in plan:
        covered |= _reaches(br, distances)
    if not covered.all():
        extra, n = _fill_holes(b, suctions, branches, starts, distances[~covered])
        plan += extra
        solves += n
    bf = b.refined(max(POLISH_ELEMENTS, int(n_elements)))
    rows, polished, coarse = [], 0, []
    for u, br, sel in plan:
        Ss = np.array([b.gap(p) for p in br.points])
        lnV = np.log([b.volume(p) for p in br.points])
        for D, xs in zip(sel, b.at_gaps(br, sel), strict=True):
            k = int(np.clip(np.searchsorted(Ss, D) - 1, 0, len(Ss) - 2))
            last = k == len(Ss) - 2
            steep = abs(lnV[k + 1] - lnV[k]) > POLISH_SLOPE * max(Ss[k + 1] - Ss[k], 1e-300)
            if (last or steep) and bf.n_elements > b.n_elements:
                rows.append(_row(bf, _polish(b, bf, xs, u, float(D)), float(D), u))
                solves += 1
                polished += 1
            else:
                coarse.append((len(rows), xs))
                rows.append(_row(b, xs, float(D), u))
        solves += sel.size
    arr = np.array(rows)
    if bf.n_elements > b.n_elements:
        flat = _flat_in_suction(arr)
        for i, xs in coarse:
            if flat[i]:
                D, u = float(arr[i, 0]), float(arr[i, 1])
                arr[i] = _row(bf, _polish(b, bf, xs, u, D), D, u)
                solves += 1
                polished += 1
    arr = arr[np.lexsort((arr[:, 1], arr[:, 0]))]
    missing = [float(D) for D in distances if not np.any(arr[:, 0] == D)]
    if missing:
        raise SolverError(f"yade export: no bridge at D* = {missing[0]:.6g} for r = {ratio:g}")
    return CapillaryTable(float(ratio), float(contact_angle), distances, suctions, arr,
                          rupture, solves, time.perf_counter() - t0, polished,
                          intermediate=len(plan) - len(suctions))


def format_table(table: CapillaryTable) -> str:
    """The file text in Yade's layout (tab-separated, 17 significant digits)."""
    out = [f"{table.ratio:g}", str(table.distances.size)]
    for block in table.blocks():
        out.append(f"{block.shape[0]}\t0\t0\t0\t0\t0\t0\t0")
        out.extend("\t".join(f"{v:.17g}" for v in row) for row in block)
    return "\n".join(out) + "\n"


def read_table(path: Path) -> tuple[float, list[np.ndarray]]:
    """Read a capillary file as Yade's ``Tableau`` does: r, then n_D blocks of rows."""
    tok = Path(path).read_text().split("\n")
    ratio = float(tok[0].split()[0])
    n_D = int(tok[1].split()[0])
    i, blocks = 2, []
    for _ in range(n_D):
        n = int(tok[i].split()[0])
        rows = np.array([[float(v) for v in tok[i + 1 + j].split()] for j in range(n)])
        if rows.shape != (n, 8):
            raise InputError(f"{path}: block {len(blocks)}: expected {n} rows of 8 numbers")
        blocks.append(rows)
        i += n + 1
    return ratio, blocks


def _one(args: tuple) -> dict:
    ratio, theta, n_u, n_d, n_el, u_top, path = args
    tab = capillary_table(ratio, theta, n_u, n_d, n_el, u_top)
    atomic_write_text(Path(path), format_table(tab))
    return {"ratio": ratio, "file": path, "rows": int(tab.rows.shape[0]),
            "suctions": int(tab.suctions.size), "distances": int(tab.distances.size),
            "max_distance": float(tab.distances[-1]), "max_suction": float(tab.suctions[-1]),
            "solves": tab.solves, "polished": tab.polished, "intermediate": tab.intermediate,
            "wall_time_s": tab.wall_time_s}


MAX_SUCTIONS, MAX_DISTANCES = 5000, 2000
"""Upper limits of the grid per file (rows = suctions x distances; Yade's usual 350 x 80
takes minutes on 2 cores)."""


def export_yade(contact_angle_deg: float, out: Path, n_suctions: int = 350,
                n_distances: int = 80, workers: int = 2, n_elements: int = DEFAULT_ELEMENTS,
                suffix: str | None = None, ratios: tuple[float, ...] = RATIOS,
                max_suction: float | None = None) -> dict:
    """Write the ten capillary files for one contact angle into ``out``, all or none.

    The tables are written into a temporary folder beside ``out`` and moved into ``out``
    only when every one of them has been computed and written: a failed or interrupted
    export leaves ``out`` as it was (the files of an earlier export untouched, a folder it
    created removed again).

    Returns a summary: ``files`` (paths), ``suffix`` (Yade's ``suffCapFiles``),
    ``contact_angle_deg``, per-file rows and times, ``wall_time_s``. ``workers``: processes
    (0 or 1: in this process, as ``sweep --workers 0``).
    """
    if not (math.isfinite(contact_angle_deg) and 0.0 <= contact_angle_deg < 89.0):
        raise InputError(f"--contact-angle = {contact_angle_deg!r} deg; allowed: [0, 89) deg")
    if workers < 0:
        raise InputError(f"--workers = {workers}; allowed: an integer >= 0 (0 or 1: in this "
                         "process)")
    for flag, n, lo, hi in (("--suctions", n_suctions, 3, MAX_SUCTIONS),
                            ("--distances", n_distances, 2, MAX_DISTANCES)):
        if not lo <= n <= hi:
            raise InputError(f"{flag} = {n}; allowed: [{lo}, {hi}] (Yade's usual: 350 "
                             "suctions, 80 distances)")
    if suffix is not None and not re.fullmatch(r"[A-Za-z0-9._+=-]{0,100}", suffix):
        raise InputError(f"--suffix = {suffix!r}; allowed: at most 100 of A-Z a-z 0-9 . _ + "
                         "= - (it ends each file name in the --out folder)")
    suffix = default_suffix(contact_angle_deg) if suffix is None else suffix
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {str(out)!r}: exists and is not a folder; give a folder")
    made = not out.exists()
    out.mkdir(parents=True, exist_ok=True)   # a path error now, not after the tables
    ok = False
    try:
        staging = _staging_folder(out)
        try:
            theta = math.radians(contact_angle_deg)
            jobs = [(r, theta, n_suctions, n_distances, n_elements, max_suction,
                     str(staging / file_name(r, suffix))) for r in ratios]
            t0 = time.perf_counter()
            results = _run_jobs(jobs, workers)
            for res in results:
                name = Path(res["file"]).name
                os.replace(staging / name, out / name)
                res["file"] = str(out / name)
            fsync_dir(out)
            ok = True
        finally:
            shutil.rmtree(staging, ignore_errors=True)
    finally:
        if made and not ok:
            with contextlib.suppress(OSError):
                out.rmdir()                  # only if still empty
    return {"files": [r["file"] for r in results], "suffix": suffix,
            "contact_angle_deg": contact_angle_deg, "n_elements": n_elements,
            "tables": results, "wall_time_s": time.perf_counter() - t0}


def _staging_folder(out: Path) -> Path:
    """A new temporary folder beside ``out`` on the same file system, so that moving a file
    from it into ``out`` is one rename (inside ``out`` when its parent is not writable or
    ``out`` is a mount point)."""
    where = out.resolve()
    if where.parent != where and where.parent.stat().st_dev == where.stat().st_dev:
        with contextlib.suppress(OSError):
            return Path(tempfile.mkdtemp(prefix=f".{where.name[:50]}.yade-partial-",
                                         dir=where.parent))
    return Path(tempfile.mkdtemp(prefix=".yade-partial-", dir=where))


def _run_jobs(jobs: list[tuple], workers: int) -> list[dict]:
    """:func:`_one` for every job, in this process (``workers <= 1``) or in a pool; the
    first failure cancels the jobs not yet started and is raised."""
    if workers <= 1:
        return [_one(j) for j in jobs]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        futures = [pool.submit(_one, j) for j in jobs]
        try:
            return [f.result() for f in futures]
        except BaseException:
            for f in futures:
                f.cancel()
            raise


# ---------------------------------------------------------------------------------------
# Proof by the consumer: Yade itself reads the files
# ---------------------------------------------------------------------------------------

_PROBE = '''
import json
cfg = json.load(open("probe.json"))
pairs = []
for k, (R1, R2, gap) in enumerate(cfg["pairs"]):
    x = 1.0 * k  # pairs 1 m apart: no cross interactions
    a = O.bodies.append(sphere(center=Vector3(x, 0, 0), radius=R1, fixed=True))
    b = O.bodies.append(sphere(center=Vector3(x, 0, R1 + R2 + gap), radius=R2, fixed=True))
    pairs.append((a, b))
law = Law2_ScGeom_CapillaryPhys_Capillarity(capillaryPressure=0.0,
        surfaceTension=cfg["sigma"], suffCapFiles=cfg["suffix"], createDistantMeniscii=True)
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=2.0)]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=2.0)],
                    [Ip2_FrictMat_FrictMat_CapillaryPhys()],
                    [Law2_ScGeom_FrictPhys_CundallStrack(neverErase=True)]),
    law,
    NewtonIntegrator(),
]
O.dt = 1e-12
out = []
for u in cfg["suctions"]:
    law.capillaryPressure = u
    O.run(1, True)
    for (a, b), (R1, R2, gap) in zip(pairs, cfg["pairs"]):
        i = O.interactions[a, b] if O.interactions.has(a, b) else None
        ok = i is not None and i.isReal
        out.append({"suction": u, "R1": R1, "R2": R2, "gap": gap,
                    "fCap": i.phys.fCap.norm() if ok else 0.0,
                    "vMeniscus": i.phys.vMeniscus if ok else 0.0,
                    "Delta1": i.phys.Delta1 if ok else 0.0,
                    "Delta2": i.phys.Delta2 if ok else 0.0})
json.dump(out, open("probe_out.json", "w"))
'''


def yade_probe(files: list[str], suffix: str, pairs: list[tuple[float, float, float]],
               suctions: list[float], surface_tension: float, workdir: Path,
               yade: str = "yade", timeout: float = 600.0) -> list[dict]:
    """Run Yade headless (``yade -n -x``) on sphere pairs with the exported files.

    Each pair ``(R1, R2, gap)`` (m) is a fixed sphere couple far from the others; for each
    suction (Pa) one time step is run and Yade's ``fCap`` (N, magnitude) and ``vMeniscus``
    (m^3) are read back from ``CapillaryPhys``. The files are copied into ``workdir`` (Yade
    opens them in its working directory).
    """
    import json
    import shutil
    import subprocess

    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    for f in files:
        shutil.copy(f, workdir / Path(f).name)
    (workdir / "probe.json").write_text(json.dumps({
        "pairs": pairs, "suctions": suctions, "sigma": surface_tension, "suffix": suffix}))
    (workdir / "probe.py").write_text(_PROBE)
    proc = subprocess.run([yade, "-n", "-x", "probe.py"], cwd=workdir, capture_output=True,
                          text=True, timeout=timeout, stdin=subprocess.DEVNULL)
    res = workdir / "probe_out.json"
    if proc.returncode != 0 or not res.exists():
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
        raise SolverError(f"yade probe failed (exit {proc.returncode}): {' | '.join(tail)}")
    return json.loads(res.read_text())
