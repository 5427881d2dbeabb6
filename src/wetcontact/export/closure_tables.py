"""The tables the ``python`` and ``c`` exports carry, as types: the refitted families
(:class:`RefitTable`) and the shipped ``calibrated-capillary`` table (:class:`CapillaryTable`,
its geometries :class:`CapillaryPart`, their bands and theta pieces, tensor trains where a
piece has them), and :class:`CapillarySource`, the one place that names what the exports
carry. Read from the package data by :mod:`wetcontact.export.closures`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

TWO_ANGLES = "sphere-wall-two-angles"
"""The table key of a wall with two contact angles (the model's ``WALL_TWO_ANGLES``)."""
PAIR_TWO_ANGLES = "sphere-sphere-two-angles"
"""The table key of two spheres with two contact angles (the model's ``PAIR_TWO_ANGLES``):
theta1 the smaller sphere's angle, theta2 the larger one's."""
TWO_ANGLE_KINDS = (TWO_ANGLES, PAIR_TWO_ANGLES)
"""The geometries whose table is in bands of the (small) sphere's angle."""
KINDS = ("sphere-wall", "sphere-sphere", TWO_ANGLES, PAIR_TWO_ANGLES)
"""The ``calibrated-capillary`` geometries the exports carry, in their order."""


@dataclass(frozen=True)
class RefitTable:
    """One refitted family read from a calibration JSON (``wetcontact calibrate``)."""

    family: str
    coefficients: tuple[float, ...]
    domain: dict[str, tuple[float, float]]
    held_out_max: float
    held_out_points: int
    source: str
    sha256: str


@dataclass(frozen=True, eq=False)
class TensorTrain:
    r"""A coefficient tensor in tensor-train form (Oseledets 2011, SIAM J. Sci. Comput. 33,
    2295), as a piece of the package data stores it (``rupture_train``, ``force_train``):

    .. math::
        C_{i_{o_1} \ldots i_{o_d}} = G_1[:, i_{o_1}, :] \, G_2[:, i_{o_2}, :] \cdots
        G_d[:, i_{o_d}, :],

    core ``G_k`` of shape (r_{k-1}, n_{o_k}, r_k) with r_0 = r_d = 1, carrying the table
    axis ``o_k = order[k]``. The Chebyshev sum of such a tensor at a point is the product
    of the matrices ``sum_m G_k[:, m, :] T_m(x_{o_k})`` (``sum_k r_{k-1} n_k r_k``
    multiply-adds), the package's
    :func:`~wetcontact.reduced_models.calibrated_capillary.train_sum`. ``tol``: the
    truncation the train was built with (the 2-norm of the singular values dropped at each
    unfolding), ``None`` when the file does not say."""

    order: tuple[int, ...]
    cores: tuple[np.ndarray, ...]
    tol: float | None = None

    @property
    def ranks(self) -> tuple[int, ...]:
        """The inner ranks r_1, ..., r_{d-1}."""
        return tuple(int(g.shape[2]) for g in self.cores[:-1])

    @property
    def shape(self) -> tuple[int, ...]:
        """The dense tensor's shape, in the table's axis order."""
        n = [0] * len(self.order)
        for g, ax in zip(self.cores, self.order, strict=True):
            n[ax] = int(g.shape[1])
        return tuple(n)

    @property
    def size(self) -> int:
        """How many numbers the cores hold."""
        return sum(int(g.size) for g in self.cores)

    @property
    def dense(self) -> np.ndarray:
        """The dense tensor C in the table's axis order (the package's
        :func:`~wetcontact.reduced_models.calibrated_capillary.train_dense`)."""
        from wetcontact.reduced_models.calibrated_capillary import train_dense

        return train_dense(list(self.cores), self.order)


@dataclass(frozen=True, eq=False)
class CapillaryPiece:
    """The tables of one theta piece of one geometry: ``rupture`` and the force table in the
    package's low-rank form, ``C^F = tensordot(force_left, force_right, 1)`` (the force
    table has the axes of ``rupture`` plus the gap axis c; ``force_left`` carries its first
    axes and the rank, ``force_right`` the rank and the others). A sphere pair's axes are
    (w, a, b[, c]), a wall's (a, b[, c]), a wall's with two angles (a, b1, b2[, c]), a sphere
    pair's with two angles (w, a, b1, b2[, c]).
    ``rupture_train``/``force_train``: the tensor trains of these two tables
    (:class:`TensorTrain`) where the package data has them (the two-angle pair table); the
    package then evaluates them, and the arrays above are the fit they were built from, so
    that :attr:`rupture_table` and :attr:`force` (what the exports carry) are the trains'.
    ``theta_lo``/``theta_hi`` (deg) bound the piece in the angle that the pieces divide
    (the one angle, or the wall's); ``None`` is the geometry's split angle (b, or b2, is
    mapped from that angle within the piece: linearly, or, if ``quadratic``, quadratically
    toward its end at the ridge, ``b = 1 - 2 sqrt((hi - theta)/(hi - lo))`` when the ridge
    is its upper end and ``b = 2 sqrt((theta - lo)/(hi - lo)) - 1`` when it is its lower
    end, the square roots' arguments clipped at 0; the package's ``theta_map`` =
    ``ridge-quadratic``). ``upper_past_ridge`` (a sphere pair's piece above the ridge, the
    package's ``upper_past_ridge``): its upper end is ``theta_hi + theta2* - theta1`` (deg),
    moving with the ridge theta2* and the small sphere's angle theta1."""

    theta_lo: float | None
    theta_hi: float | None
    rupture: np.ndarray
    force_left: np.ndarray
    force_right: np.ndarray
    quadratic: bool = False
    upper_past_ridge: bool = False
    rupture_train: TensorTrain | None = None
    force_train: TensorTrain | None = None

    @property
    def rank(self) -> int:
        """The rank r of the force table's low-rank factorisation."""
        return int(self.force_left.shape[-1])

    @property
    def n_left(self) -> int:
        """How many of the force table's leading axes ``force_left`` carries."""
        return self.force_left.ndim - 1

    @property
    def force_shape(self) -> tuple[int, ...]:
        """The dense force table's shape: the rupture table's axes plus the gap axis."""
        return (*self.force_left.shape[:-1], *self.force_right.shape[1:])

    @property
    def rupture_table(self) -> np.ndarray:
        """The rupture table the package evaluates: its train's dense tensor
        (:attr:`TensorTrain.dense`) where it has one, else ``rupture``."""
        return self.rupture if self.rupture_train is None else self.rupture_train.dense

    @property
    def force(self) -> np.ndarray:
        """The force table the package evaluates, dense: its train's dense tensor where it
        has one, else ``sum_k L[..., k] R[k, ...]`` (the json export writes it; the python
        and C exports evaluate the train, or the factors)."""
        if self.force_train is not None:
            return self.force_train.dense
        return np.tensordot(self.force_left, self.force_right, axes=1)


@dataclass(frozen=True, eq=False)
class CapillaryBand:
    """One band of a two-angle table (a wall, or a sphere pair): the (small) sphere angles
    ``theta_sphere_lo`` ... ``theta_sphere_hi`` (deg) it covers (b1 is that angle mapped
    linearly from the range to [-1, 1]: ``b1 = (2 theta_s - lo - hi)/(hi - lo)``), its ridge
    series ``split`` (the other solid's angle of the rupture distance's ridge, a tensor
    Chebyshev series in the lead coordinates and b1: shape (n_a, n_b1) on a wall,
    (n_w, n_a, n_b1) for a pair) and its pieces, which divide the other solid's angle at
    that ridge. An end ``None`` is the onset angle theta_on of the part's ``onset`` series
    at the point's own lead coordinates (``a``, or (w, a)): the range, and b1's map, then
    differ from point to point."""

    theta_sphere_lo: float | None
    theta_sphere_hi: float | None
    pieces: tuple[CapillaryPiece, ...]
    split: np.ndarray

    @property
    def range_text(self) -> str:
        """``[lo, hi] deg``, an onset end as ``theta_on(V)``."""
        return f"[{sphere_end_text(self.theta_sphere_lo)}, " \
               f"{sphere_end_text(self.theta_sphere_hi)}] deg"


ONSET_TEXT = "theta_on(V)"
"""How the exports' texts name a band's end at the onset angle (``None``)."""


def sphere_end_text(x: float | None) -> str:
    """A band's end of the sphere angle as text: the number (``%g``), or
    :data:`ONSET_TEXT` for the onset angle."""
    return ONSET_TEXT if x is None else f"{x:g}"


@dataclass(frozen=True, eq=False)
class CapillaryPart:
    """One geometry of the shipped ``calibrated-capillary`` table.

    One angle (``sphere-wall``, ``sphere-sphere``): its theta pieces (a point belongs to
    the first whose upper end is at or above its angle) and, where a piece ends at the
    split angle, that angle (deg) as a Chebyshev series (``split``) in the volume
    coordinate ``a``; ``bands`` is empty.

    Two angles (``two_angles``: a wall, ``sphere-wall-two-angles``, or a sphere pair,
    ``sphere-sphere-two-angles``, theta1 the small sphere's angle): ``bands``, the table
    split in the (small) sphere's angle (a point belongs to the first band whose upper
    ``theta_sphere_hi``, evaluated at the point, is at or above that angle), each a
    complete table with its own b1 range, ridge series and pieces (:class:`CapillaryBand`);
    ``pieces`` is empty and ``split`` ``None``. ``onset``: the package data's
    ``theta_sphere_split``, the sphere angle theta_on (deg) where the ridge's jump appears
    as a Chebyshev series in the lead coordinates, ``theta_on = sum_k o_k T_k(a)`` on a
    wall (1-D), ``sum_ij o_ij T_i(w) T_j(a)`` for a pair (2-D), the value of a band's end
    ``None``; ``None`` when the table has no such series (then no band ends there).

    ``held_out``: the error table of the geometry; ``held_out_strata``: those of its
    stress strata (e.g. ``near_ridge``), by name."""

    kind: str
    pieces: tuple[CapillaryPiece, ...]
    split: np.ndarray | None
    held_out: dict[str, Any]
    held_out_strata: dict[str, dict[str, Any]] = field(default_factory=dict)
    bands: tuple[CapillaryBand, ...] = ()
    onset: np.ndarray | None = None

    @property
    def two_angles(self) -> bool:
        """Two contact angles: a wall with the sphere's and its own, or two spheres."""
        return self.kind in TWO_ANGLE_KINDS

    @property
    def pair(self) -> bool:
        """A sphere pair: the lead coordinates are (w, a), not a alone."""
        return self.kind in ("sphere-sphere", PAIR_TWO_ANGLES)

    @property
    def sections(self) -> tuple[CapillaryBand | CapillaryPart, ...]:
        """What holds pieces and a split series: the bands (two angles), or the part."""
        return self.bands or (self,)

    @property
    def all_pieces(self) -> tuple[CapillaryPiece, ...]:
        """Every piece of the geometry, band after band."""
        return tuple(p for sec in self.sections for p in sec.pieces)


@dataclass(frozen=True, eq=False)
class CapillaryTable:
    """The shipped ``calibrated-capillary`` table (package data) and the model's domain."""

    parts: dict[str, CapillaryPart]
    v_range: tuple[float, float]
    theta_range_deg: tuple[float, float]
    ratio_range: tuple[float, float]
    angle_tol: float
    w_max: float
    source: str
    sha256: str

    def held_out_text(self, kind: str) -> str:
        """``force max X (n points), rupture distance max Y (m)`` of one geometry, and of
        each of its stress strata (``; near_ridge: force max ...``)."""
        part = self.parts[kind]

        def text(ho: dict[str, Any]) -> str:
            if "force" not in ho or "rupture_distance" not in ho:
                return "held-out errors not in the package data"
            f, r = ho["force"], ho["rupture_distance"]
            return (f"force max {f['max']:.2g} ({f['points']} points), rupture distance max "
                    f"{r['max']:.2g} ({r['points']} bridges)")

        return "; ".join([text(part.held_out)] + [
            f"{name.replace('_', ' ')}: {text(ho)}" for name, ho in part.held_out_strata.items()])


@dataclass(frozen=True)
class CapillarySource:
    """The capillary tables the exports carry.

    ``table``: the shipped ``calibrated-capillary`` closure (``capillary_force``,
    ``rupture_distance``); ``force`` and ``rupture``: the refitted ``willett`` force and
    ``lian-rupture`` distance (``capillary_force_refit``, ``rupture_distance_refit``).
    """

    table: CapillaryTable
    force: RefitTable
    rupture: RefitTable

    @property
    def shipped_label(self) -> str:
        shipped = "; ".join(f"{k}: {self.table.held_out_text(k)}" for k in self.table.parts)
        missing = [k for k in KINDS if k not in self.table.parts]
        return ("the shipped 'calibrated-capillary' closure (held-out relative error "
                f"against meniscus, {shipped}"
                + (f"; {', '.join(missing)}: not generated, NaN" if missing else "") + ")")

    @property
    def refit_label(self) -> str:
        return (f"'{self.force.family}' refit (held-out max error "
                f"{100 * self.force.held_out_max:.1f} % against meniscus, "
                f"{self.force.held_out_points} points) and '{self.rupture.family}' refit "
                f"(held-out max error {100 * self.rupture.held_out_max:.1f} %, "
                f"{self.rupture.held_out_points} points)")

    @property
    def label(self) -> str:
        return (f"capillary_force and rupture_distance = {self.shipped_label}; "
                "capillary_force_refit and rupture_distance_refit = REFITTED families, not "
                f"a shipped closure: {self.refit_label}")
