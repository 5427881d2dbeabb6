r"""Calibrated capillary closure (level 0, ``calibrated-capillary``): tensor Chebyshev
interpolants of the ``meniscus`` force and rupture distance, one contact angle per pair, or
two (a sphere's and a wall's, or each sphere's).

Domain: a pendular bridge of volume V between a sphere and a wall, or two spheres of radii
``R_s <= R_l`` (radius ratio ``r = R_l/R_s`` in [1, 10]), with ``v = V/R_s^3`` in
[1e-4, 0.1] and **the same** contact angle theta in [0, 70 deg] on both solids (what Yade's
capillary law and Willett's fit assume), or two: on a wall the sphere's theta_s and the
wall's theta_w, between spheres the small sphere's theta1 and the large one's theta2, each
in [0, 70 deg]; no gravity, any gap (0 beyond rupture). Outside, the model refuses and
names ``meniscus``.

Form, with ``R* = R_s R_l/(R_s + R_l)`` (``R* = R`` on a wall):

.. math::
    S_c = R_s\, v^{1/3} \exp\Big(\sum C^{rup}_{ij\ldots} T_i(a) T_j(b) \ldots\Big),\qquad
    F = 2\pi\sigma R^* (\cos\theta_1 + \cos\theta_2)\,
        \exp\Big(\sum C^{F}_{ijk\ldots} T_i(a) T_j(b) T_k(c) \ldots\Big),

the Derjaguin force at contact (Derjaguin 1934; PHYSICS.md section 2) times a smooth
correction, in the coordinates of :mod:`.coordinates` (volume, angles, radius ratio, gap).
Source: the coefficients interpolate this package's ``meniscus`` solver (Young-Laplace; no
published form) at tensor Chebyshev points (:mod:`wetcontact.generate.calibrated_capillary`,
:mod:`wetcontact.generate.calibrated_capillary_pairs`); the package data
``data/calibrated_capillary.json`` holds them with their held-out error tables.

Accuracy: held-out maxima (rupture distance / force; goals 5e-4 / 1e-3; gaps to 0.999 S_c)
with one angle 6.6e-6 / 2.0e-5 on a wall, 7.0e-6 / 1.7e-5 between spheres; with two angles
1.2e-5 / 2.0e-5 on a wall, 2.5e-4 / 2.6e-4 between spheres, uniformly; the strata where the
tables are hardest (corners, the ridge and its jump, nearly equal spheres) in :mod:`.model`.

Modules: :mod:`.coordinates` (the domain and the maps to [-1, 1]), :mod:`.kernel` (the
tables' evaluation, standalone: the python export ships it), :mod:`.shipped` (the package
data's table and :func:`force_star` on it), :mod:`.model` (the registered model,
:class:`CalibratedCapillary`, and its error bound). How the tables were built and measured:
the guide's page ``docs/calibrated_capillary.md``.
"""

from wetcontact.reduced_models.calibrated_capillary.coordinates import (
    ANGLE_TOL,
    PAIR_TWO_ANGLES,
    RATIO_RANGE,
    RIDGE_QUADRATIC,
    RIDGE_TOP_DEG,
    THETA_RANGE_DEG,
    TWO_ANGLE_TABLES,
    UPPER_PAST_RIDGE,
    V_RANGE,
    W_MAX,
    WALL_TWO_ANGLES,
    Lead,
    gap_coordinate,
    gap_from_coordinate,
    lead_list,
    piece_angle,
    piece_coordinate,
    piece_range,
    ratio_coordinate,
    sphere_coordinate,
    volume_coordinate,
)
from wetcontact.reduced_models.calibrated_capillary.coordinates import (
    _map as _map,
)
from wetcontact.reduced_models.calibrated_capillary.coordinates import (
    _take as _take,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    CHUNK_FLOATS,
    ONSET_KEY,
    PRECISIONS,
    TABLE_FIELDS,
    TRAIN_CHUNK,
    TRAIN_FIELDS,
    as_arrays,
    band_index,
    chebyshev_tensor,
    low_rank_rows,
    onset_deg,
    piece_chunk,
    reduced_star,
    sphere_range,
    table_pieces,
    table_star,
    theta_split_deg,
    train_dense,
    train_shape,
    train_sum,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    _band_onset as _band_onset,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    _by_band as _by_band,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    _cheb_rows as _cheb_rows,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    _outer as _outer,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    _outer_rows as _outer_rows,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    _piece as _piece,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    _pieces as _pieces,
)
from wetcontact.reduced_models.calibrated_capillary.kernel import (
    _series_2d as _series_2d,
)
from wetcontact.reduced_models.calibrated_capillary.model import (
    NEAR_RIDGE_MARGIN,
    RIDGE_JUMP_MAX,
    RIDGE_STRATA,
    RIDGE_TOP_ZONE_DEG,
    RIDGE_WINDOW_DEG,
    RIDGE_WINDOW_TOP,
    RIDGE_ZONE_DEG,
    SPURIOUS,
    CalibratedCapillary,
    ridge_window_deg,
)
from wetcontact.reduced_models.calibrated_capillary.shipped import (
    CAPILLARY_FILE,
    capillary_table,
    force_star,
    ridge_deg,
    rupture_star,
)
from wetcontact.reduced_models.calibrated_capillary.shipped import (
    _entry as _entry,
)

__all__ = [
    "ANGLE_TOL",
    "CAPILLARY_FILE",
    "CHUNK_FLOATS",
    "CalibratedCapillary",
    "Lead",
    "NEAR_RIDGE_MARGIN",
    "ONSET_KEY",
    "PAIR_TWO_ANGLES",
    "PRECISIONS",
    "RATIO_RANGE",
    "RIDGE_JUMP_MAX",
    "RIDGE_QUADRATIC",
    "RIDGE_STRATA",
    "RIDGE_TOP_DEG",
    "RIDGE_TOP_ZONE_DEG",
    "RIDGE_WINDOW_DEG",
    "RIDGE_WINDOW_TOP",
    "RIDGE_ZONE_DEG",
    "SPURIOUS",
    "TABLE_FIELDS",
    "THETA_RANGE_DEG",
    "TRAIN_CHUNK",
    "TRAIN_FIELDS",
    "TWO_ANGLE_TABLES",
    "UPPER_PAST_RIDGE",
    "V_RANGE",
    "WALL_TWO_ANGLES",
    "W_MAX",
    "as_arrays",
    "band_index",
    "capillary_table",
    "chebyshev_tensor",
    "force_star",
    "gap_coordinate",
    "gap_from_coordinate",
    "lead_list",
    "low_rank_rows",
    "onset_deg",
    "piece_angle",
    "piece_chunk",
    "piece_coordinate",
    "piece_range",
    "ratio_coordinate",
    "reduced_star",
    "ridge_deg",
    "ridge_window_deg",
    "rupture_star",
    "sphere_coordinate",
    "sphere_range",
    "table_pieces",
    "table_star",
    "theta_split_deg",
    "train_dense",
    "train_shape",
    "train_sum",
    "volume_coordinate",
]
