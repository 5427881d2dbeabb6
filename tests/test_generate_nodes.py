"""The capillary generators' node jobs, listed without solving, and how far a node's values
move on a coarser meridian (issue 54's regeneration: a faster solve per node)."""

import json
import math

import numpy as np
import pytest

from wetcontact.generate import calibrated_capillary as gen
from wetcontact.generate import calibrated_capillary_pairs as p2
from wetcontact.reduced_models import DATA_DIR
from wetcontact.reduced_models import calibrated_capillary as cc

NODE_ELEMENTS = 64
NODE_TOL = 5e-6
"""Largest change of log S_c and of log q (the quantities the tables interpolate) at 64
meridian elements against the default 128, on the two-angle pair table's nodes. Source:
``benchmarks/bench_regeneration.py`` (``node_solve_elements_measured``) and 24 seeded nodes
of that table, whose largest changes were 2.0e-7 (log S_c) and 7.6e-7 (log q), 1.4x
faster; this is 6x that, and 1/7 of the smallest held-out maximum of the two-angle tables
(3.5e-5, the pair table's rupture distance on the low-angle stratum). Not for the
one-angle tables: their corner strata hold S_c to 3e-8, below this change."""


@pytest.fixture(scope="module")
def pair_entry():
    data = json.loads((DATA_DIR / cc.CAPILLARY_FILE).read_text())
    return data[cc.PAIR_TWO_ANGLES]


def _pair_jobs(entry, band, piece):
    spec, nodes = p2.PAIR_PIECES[piece], p2.pair_band_nodes(band)[piece]
    b = entry["bands"][band]
    return p2.pair_piece_jobs(spec, nodes[3], entry[cc.ONSET_KEY], b["theta_split"],
                              nodes[0], tuple(b["theta_sphere_deg"])), nodes


@pytest.mark.parametrize(("band", "piece"), [(0, 0), (1, 1)])
def test_pair_piece_jobs_are_the_tensor_grid(pair_entry, band, piece):
    """One job per (w, a, b1, b2) node, each a distinct branch (its node-cache key)."""
    (jobs, vs, shape), nodes = _pair_jobs(pair_entry, band, piece)
    assert shape == tuple(nodes[:-1])
    assert len(jobs) == math.prod(nodes[:-1])
    assert len({gen.NodeCache.key(j) for j in jobs}) == len(jobs)
    assert len(vs) == nodes[1]


def test_wall_piece_jobs_are_the_tensor_grid():
    data = json.loads((DATA_DIR / cc.CAPILLARY_FILE).read_text())
    e = data[cc.WALL_TWO_ANGLES]
    spec = gen.band_pieces(cc.WALL_TWO_ANGLES, 1)[1]
    jobs, _, gauss_b = gen.piece_jobs(cc.WALL_TWO_ANGLES, spec, e["bands"][1]["theta_split"],
                                      tuple(e["bands"][1]["theta_sphere_deg"]),
                                      e.get(cc.ONSET_KEY))
    assert gauss_b
    assert len(jobs) == math.prod(spec["nodes"][:-1])


def test_node_values_on_a_coarser_meridian(pair_entry):
    """Three seeded nodes of the pair table: log S_c and log q at 64 elements within
    :data:`NODE_TOL` of the default (128)."""
    rng = np.random.default_rng(54)
    for band, piece in ((0, 0), (1, 1), (2, 0)):
        (jobs, _, _), _ = _pair_jobs(pair_entry, band, piece)
        _, kind, r, v, t1, c, t2 = jobs[int(rng.integers(len(jobs)))]
        s_ref, q_ref = gen.solve_branch(kind, r, v, t1, c, t2)
        s, q = gen.solve_branch(kind, r, v, t1, c, t2, n_elements=NODE_ELEMENTS)
        assert abs(math.log(s / s_ref)) < NODE_TOL
        assert np.max(np.abs(np.log(q / q_ref))) < NODE_TOL
