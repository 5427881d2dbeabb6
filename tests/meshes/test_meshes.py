"""gmsh builders, meshio round trip into scikit-fem, named boundaries, gap grading, cache."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from wetcontact.errors import InputError
from wetcontact.meshes import builders
from wetcontact.meshes.builders import Resolution
from wetcontact.meshes.cache import clear_memo, get_mesh, get_meshio, mesh_key
from wetcontact.meshes.io import to_skfem
from wetcontact.solver.stokes import gap_elements

COARSE = Resolution(n_gap=3, h_sphere=0.15, growth=0.4, far=1000.0, n_film=3)


def _facet_points(mesh, name):
    f = mesh.boundaries[name]
    return mesh.p[:, mesh.facets[:, f].ravel()]


@pytest.fixture
def cache(tmp_path):
    clear_memo()
    yield tmp_path
    clear_memo()


@pytest.mark.parametrize("gap", [1e-4, 1e-2, 1.0])
def test_sphere_wall_groups_lie_on_their_geometry(gap):
    mesh = to_skfem(builders.sphere_wall(gap, COARSE))
    assert set(mesh.boundaries) == {"axis", "wall", "sphere", "far"}
    c = 1.0 + gap
    r, z = _facet_points(mesh, "sphere")
    np.testing.assert_allclose(np.hypot(r, z - c), 1.0, atol=1e-12)
    assert np.all(_facet_points(mesh, "wall")[1] == 0.0)
    assert np.all(_facet_points(mesh, "axis")[0] == 0.0)
    r, z = _facet_points(mesh, "far")
    np.testing.assert_allclose(np.hypot(r, z), COARSE.far, rtol=1e-12)
    # every boundary facet is in exactly one group
    named = np.concatenate([mesh.boundaries[k] for k in mesh.boundaries])
    assert np.array_equal(np.sort(named), np.sort(mesh.boundary_facets()))


def test_second_order_nodes_are_on_the_sphere():
    """Isoparametric geometry: mid-edge nodes of sphere facets sit on the exact circle."""
    gap = 0.1
    mesh = to_skfem(builders.sphere_wall(gap, COARSE))
    from skfem import Basis, ElementTriP2

    basis = Basis(mesh, ElementTriP2())
    mids = basis.get_dofs("sphere").all()
    r, z = basis.doflocs[:, mids]
    assert mids.size > mesh.boundaries["sphere"].size  # vertices and edge nodes
    np.testing.assert_allclose(np.hypot(r, z - 1.0 - gap), 1.0, atol=1e-12)
    # the sphere's surface area 4 pi R^2 = 2 pi int r ds, to P2-geometry accuracy
    from skfem import FacetBasis, Functional

    fb = FacetBasis(mesh, ElementTriP2(), facets=mesh.boundaries["sphere"])
    # (straight-sided edges of this size would miss it by about 1e-3)
    assert Functional(lambda w: w.x[0]).assemble(fb) == pytest.approx(2.0, rel=1e-5)


@pytest.mark.parametrize("gap", [1e-4, 1e-3, 1e-2, 0.1])
def test_elements_across_the_gap_are_constant(gap):
    res = Resolution(n_gap=4, h_sphere=0.1, growth=0.3, far=100.0)
    mesh = to_skfem(builders.sphere_wall(gap, res))
    assert 4 <= gap_elements(mesh, 0.0, gap) <= 6


def test_two_sphere_and_symmetry_meshes():
    full = to_skfem(builders.sphere_sphere(1e-3, COARSE))
    assert set(full.boundaries) == {"axis", "sphere", "sphere2", "far"}
    r, z = _facet_points(full, "sphere2")
    np.testing.assert_allclose(np.hypot(r, z + 1.0005), 1.0, atol=1e-12)
    assert gap_elements(full, -5e-4, 5e-4) >= 2 * COARSE.n_gap
    half = to_skfem(builders.sphere_wall(5e-4, COARSE, plane="symmetry"))
    assert set(half.boundaries) == {"axis", "symmetry", "sphere", "far"}
    with pytest.raises(InputError, match="plane"):
        builders.sphere_wall(0.1, COARSE, plane="mirror")


def test_film_mesh_has_flat_free_surface_at_delta():
    gap, film = 0.01, 0.05
    mesh = to_skfem(builders.sphere_film(gap, film, COARSE))
    assert set(mesh.boundaries) == {"axis", "wall", "sphere", "free_surface", "far"}
    r, z = _facet_points(mesh, "free_surface")
    np.testing.assert_allclose(z, film, atol=1e-14)
    assert r.min() == pytest.approx(builders.film_contact_radius(gap, film), rel=1e-12, abs=0)
    assert mesh.p[1].max() == pytest.approx(film, abs=1e-14)
    with pytest.raises(InputError, match="film thickness"):
        builders.sphere_film(0.1, 0.05, COARSE)


def test_film_mesh_is_graded_to_the_corner():
    """The smallest free-surface edge, at the corner (r_c, delta), is ``film_corner`` delta
    (gmsh's size field within a factor 2), and the size floors at ``MIN_CORNER``."""
    gap, film = 0.01, 0.05
    for corner, expect in ((1e-3, 1e-3 * film), (1e-6, builders.MIN_CORNER)):
        res = dataclasses.replace(COARSE, film_corner=corner)
        mesh = to_skfem(builders.sphere_film(gap, film, res))
        f = mesh.facets[:, mesh.boundaries["free_surface"]]
        p0, p1 = mesh.p[:, f[0]], mesh.p[:, f[1]]
        length = np.hypot(*(p1 - p0))
        rc = builders.film_contact_radius(gap, film)
        at = np.argmin(np.minimum(p0[0], p1[0]))
        assert min(p0[0, at], p1[0, at]) == pytest.approx(rc, rel=1e-12, abs=0)
        assert 0.5 * expect < length[at] < 2.0 * expect
        assert length[at] == pytest.approx(length.min(), abs=0)  # lengths down to 1e-7
    with pytest.raises(InputError, match="film_corner"):
        builders.Resolution(film_corner=0.0)


def test_bridge_mesh_follows_the_toroidal_profile():
    gap, b = 0.05, math.radians(30)
    prof = builders.toroidal_bridge_profile(gap, b, contact_angle=math.radians(30))
    # the arc starts on the wall, ends on the sphere, and is a circle
    assert prof[0, 1] == 0.0
    assert math.hypot(prof[-1, 0], prof[-1, 1] - 1 - gap) == pytest.approx(1.0, abs=1e-12)
    mesh = to_skfem(builders.sphere_bridge(gap, prof, COARSE))
    assert set(mesh.boundaries) == {"axis", "wall", "sphere", "free_surface"}
    r, z = _facet_points(mesh, "free_surface")
    centre = prof[0, 0] + np.hypot(*(prof[-1] - prof[0])) * 0  # placeholder, replaced below
    r1 = (2 * (1 - math.cos(b)) + 2 * gap) / (2 * math.cos(b + math.radians(30)))
    centre = prof[0, 0] + r1
    np.testing.assert_allclose(np.hypot(r - centre, z), r1, rtol=2e-4)  # spline through arc
    with pytest.raises(InputError, match="start on the wall"):
        builders.sphere_bridge(gap, prof[::-1], COARSE)


def test_bridge_mesh_graded_towards_the_contact_lines():
    """contact_size: edges at both contact lines are about that size (for a slip length)."""
    gap, b, th = 0.01, math.radians(20), math.radians(20)
    prof = builders.toroidal_bridge_profile(gap, b, contact_angle=th)
    mesh = to_skfem(builders.sphere_bridge(gap, prof, COARSE, contact_size=1e-4))
    plain = to_skfem(builders.sphere_bridge(gap, prof, COARSE))
    fs = mesh.boundaries["free_surface"]
    ends = mesh.p[:, mesh.facets[:, fs]]
    length = np.hypot(*(ends[:, 1] - ends[:, 0]))
    for corner in (prof[0], prof[-1]):
        near = np.hypot(*(ends[:, 0] - corner[:, None])) < 1e-9
        near |= np.hypot(*(ends[:, 1] - corner[:, None])) < 1e-9
        assert near.sum() == 1 and 0.3e-4 < length[near][0] < 3e-4
    assert mesh.t.shape[1] > plain.t.shape[1]
    with pytest.raises(InputError, match="contact_size"):
        builders.sphere_bridge(gap, prof, COARSE, contact_size=0.0)


def test_unequal_sphere_mesh_has_both_radii_and_the_gap_grading():
    mesh = to_skfem(builders.sphere_sphere(0.01, COARSE, radius2=2.0))
    r, z = _facet_points(mesh, "sphere2")
    np.testing.assert_allclose(np.hypot(r, z + 2.005), 2.0, atol=1e-9)
    r, z = _facet_points(mesh, "sphere")
    np.testing.assert_allclose(np.hypot(r, z - 1.005), 1.0, atol=1e-9)
    assert gap_elements(mesh, -0.005, 0.005) >= 2 * COARSE.n_gap
    with pytest.raises(InputError, match="radius ratio"):
        builders.sphere_sphere(0.01, COARSE, radius2=100.0)


def test_cache_hit_and_key(cache):
    k1 = mesh_key("sphere_wall", gap=0.1, res=COARSE, plane="wall")
    assert k1 != mesh_key("sphere_wall", gap=0.1000001, res=COARSE, plane="wall")
    m1, hit1 = get_meshio("sphere_wall", cache=cache, gap=0.1, res=COARSE, plane="wall")
    m2, hit2 = get_meshio("sphere_wall", cache=cache, gap=0.1, res=COARSE, plane="wall")
    assert (hit1, hit2) == (False, True)
    assert len(list(cache.glob("sphere_wall-*.msh"))) == 1
    np.testing.assert_array_equal(m1.points, m2.points)
    a = get_mesh("sphere_wall", cache=cache, gap=0.1, res=COARSE, plane="wall")
    assert a is get_mesh("sphere_wall", cache=cache, gap=0.1, res=COARSE, plane="wall")
    assert set(a.boundaries) == {"axis", "wall", "sphere", "far"}


def test_cache_dir_from_environment(monkeypatch, tmp_path):
    from wetcontact.meshes.cache import cache_dir

    monkeypatch.setenv("WETCONTACT_CACHE", str(tmp_path))
    assert cache_dir() == tmp_path / "meshes"


@pytest.mark.parametrize("bad", [dict(n_gap=0), dict(h_sphere=0.0), dict(growth=5.0),
                                 dict(far=1.0)])
def test_resolution_rejects_bad_values(bad):
    with pytest.raises(InputError):
        Resolution(**bad)


def test_pvd_collection_sorts_by_time_and_numbers_parts(tmp_path):
    """write_pvd: time steps increasing, two files at one time are parts 0 and 1, file names
    relative to the collection's folder, valid XML."""
    import xml.etree.ElementTree as ET

    from wetcontact.meshes.io import write_pvd

    (tmp_path / "sub").mkdir()
    files = [(2e-6, tmp_path / "b.vtu"), (1e-6, tmp_path / "sub" / "a.vtu"),
             (2e-6, tmp_path / "c.vtu")]
    path = write_pvd(tmp_path / "all.pvd", files)
    sets = ET.parse(path).getroot().findall("./Collection/DataSet")
    assert [(float(d.get("timestep")), d.get("part"), d.get("file")) for d in sets] == [
        (1e-6, "0", "sub/a.vtu"), (2e-6, "0", "b.vtu"), (2e-6, "1", "c.vtu")]
