"""Weak forms of axisymmetric Stokes flow in the meridian half-plane (r, z), eta = 1, the
volume element 2 pi r dr dz with the 2 pi dropped (restored in the force): the viscous form
with the hoop term, the divergence form, the sphere's axial traction, the surface work and
Navier's slip friction (the equations are in :mod:`wetcontact.solver.stokes.solve`)."""

from __future__ import annotations

from skfem import BilinearForm, Functional


@BilinearForm
def viscous_form(u, w, x):
    """Axisymmetric viscous dissipation form a(u, w), eta = 1, including the hoop term."""
    r = x.x[0]
    du, dw = u.grad, w.grad
    erz_u = du[0][1] + du[1][0]
    erz_w = dw[0][1] + dw[1][0]
    return 2.0 * (du[0][0] * dw[0][0] + du[1][1] * dw[1][1]) * r + erz_u * erz_w * r + (
        2.0 * u[0] * w[0] / r
    )


@BilinearForm
def divergence_form(w, q, x):
    """r-weighted divergence b(w, q) = q (r d_r w_r + w_r + r d_z w_z)."""
    r = x.x[0]
    return q * (r * (w.grad[0][0] + w.grad[1][1]) + w[0])


@Functional
def traction_z(x):
    """Axial traction on the sphere, r-weighted: -(sigma n)_z r with n out of the fluid."""
    u, p = x["u"], x["p"]
    n = x.n
    r = x.x[0]
    szr = u.grad[0][1] + u.grad[1][0]
    szz = -p + 2.0 * u.grad[1][1]
    return -(szr * n[0] + szz * n[1]) * r


@Functional
def surface_work(x):
    """Power of the normal traction on a boundary, r-weighted: ``u_n sigma_nn r``.

    ``sigma_nn = -p + 2 eta n.e(u).n`` (eta = 1; ``viscous`` = 0 drops the viscous part, so
    with p = -1 this is the r-weighted volume flux ``u_n r``).
    """
    u, p = x["u"], x["p"]
    n = x.n
    r = x.x[0]
    g = u.grad
    enn = g[0][0] * n[0] * n[0] + (g[0][1] + g[1][0]) * n[0] * n[1] + g[1][1] * n[1] * n[1]
    un = u[0] * n[0] + u[1] * n[1]
    return un * (-p + 2.0 * x.get("viscous", 1.0) * enn) * r


@BilinearForm
def navier_slip_form(u, w, x):
    """Navier slip friction on a solid boundary, r-weighted: (eta/b) u_t w_t r, eta = 1.

    With the normal velocity fixed to the body's, the tangential traction balances the slip
    velocity, ``sigma_nt = (eta/b)(u_t - U_t)`` (Navier 1823); integrating the momentum
    equation by parts leaves this boundary term (``friction`` = 1/b).
    """
    n = x.n
    ut = u[1] * n[0] - u[0] * n[1]
    wt = w[1] * n[0] - w[0] * n[1]
    return x["friction"] * ut * wt * x.x[0]
