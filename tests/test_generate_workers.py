"""The generators' job map (:mod:`wetcontact.generate.workers`): on Dask workers (the sweep's
local cluster) the same results in job order as in this process, each handed to
``on_result``, and the command line that asks for them."""

import math

import numpy as np
import pytest

from wetcontact.generate import calibrated_capillary as gen
from wetcontact.generate.__main__ import parser
from wetcontact.generate.workers import DaskWorkers, chunk_size, map_jobs, open_workers


@pytest.fixture(scope="module")
def dask_workers():
    with open_workers(1, dask=True) as workers:
        yield workers


def test_open_workers_without_dask_is_the_count():
    with open_workers(3) as workers:
        assert workers == 3


def test_dask_map_keeps_job_order(dask_workers):
    assert isinstance(dask_workers, DaskWorkers)
    jobs = [float(k) for k in range(37)]  # 37 // 8: chunks of 4, the last one short
    seen = []
    got = map_jobs(math.sqrt, jobs, dask_workers, "sqrt",
                   on_result=lambda j, r: seen.append((j, r)))
    assert got == [math.sqrt(j) for j in jobs]
    assert sorted(seen) == [(j, math.sqrt(j)) for j in jobs]


def test_dask_node_solves_match_this_process(dask_workers):
    """Two node branches of the two-angle wall table solved on a Dask worker: the same S_c
    and forces as in this process (the same code: to round-off)."""
    c = gen.lobatto(5)
    jobs = [((0,), "sphere-wall-two-angles", None, 0.01, math.radians(20.0), c,
             math.radians(t2)) for t2 in (10.0, 30.0)]
    here = map_jobs(gen._node_job, jobs, 1, "here")
    there = map_jobs(gen._node_job, jobs, dask_workers, "there")
    for (i1, s1, q1), (i2, s2, q2) in zip(here, there, strict=True):
        assert i1 == i2
        assert s2 == pytest.approx(s1, rel=1e-12)
        np.testing.assert_allclose(q2, q1, rtol=1e-12)


def test_chunks():
    assert chunk_size(10, 2) == 1
    assert chunk_size(10_000, 4) == 4


@pytest.mark.parametrize("argv", [["calibrated-capillary", "--dask", "--workers", "4"],
                                  ["all", "--scheduler", "tcp://127.0.0.1:8786"]])
def test_command_line_asks_for_dask(argv):
    args = parser().parse_args(argv)
    assert args.dask or args.scheduler
