"""Offline builders of the package data (``reduced_models/data``): what regenerates each
shipped table from its references, and nothing a closure or a solver needs at run time.

``python -m wetcontact.generate TABLE|all [--workers N]`` (:mod:`.__main__`; ``list`` names
the tables). Modules: :mod:`.calibrated_viscous` (``calibrated_viscous.json``),
:mod:`.calibrated_capillary` (``calibrated_capillary.json``: the one-angle tables, the
two-angle wall table, and the machinery they share: Chebyshev-Lobatto nodes, meniscus
branches, tensor trains, held-out designs), :mod:`.calibrated_capillary_pairs` (its two-angle
sphere-pair table, and the refits of either two-angle table's bands), :mod:`.bounds`
(``bounds.json``: the closures' measured error bounds). Only this package and
:mod:`wetcontact.cli` import it (an import-linter contract).
"""
