"""One wet head-on impact in Yade (Debian ``yade`` 2023.02a), measured by Yade itself.

Run headless:  ``yade -n -x benchmarks/dem/yade_impact.py [options]``  (prints one JSON
document on the last line of stdout; ``--out FILE`` also writes it).

Scene (no gravity, ``NewtonIntegrator(damping=0)``): a sphere (R = 1 mm, rho = 2500 kg/m3)
moves along +x with the approach speed v0 toward a second, equal sphere that is either
*fixed* (``--partner fixed``, the default: ``fixed=True``, it keeps its mass in Yade's
bookkeeping) or *free* and moving at -v0/2 while the first moves at +v0/2
(``--partner pair``). The surfaces start ``--gap`` apart (default 0.3 mm, beyond the
rupture distance, so no force acts on approach and the rebound is measured in free flight).

Laws (``ViscElCapMat`` + ``Ip2_ViscElCapMat_ViscElCapMat_ViscElCapPhys`` +
``Law2_ScGeom_ViscElCapPhys_Basic``; see README.md for the formulas and source lines):
solid contact is Yade's linear spring-dashpot built from (tc, en, et); the liquid bridge
forms at the first contact, acts only while the surfaces are apart (s > 0) and breaks at
Willett's rupture distance; ``--law lubrication`` runs Yade's implicit lubrication law
instead (``Ip2_FrictMat_FrictMat_LubricationPhys`` + ``Law2_ScGeom_ImplicitLubricationPhys``).

Measured: e = (rebound speed) / v0, both relative normal speeds, the rebound one taken when
the gap comes back to the start gap (after the bridge has ruptured: free flight); the
contact duration (gap <= 0, crossings interpolated linearly between steps); the gap at
which the bridge ruptured; the largest overlap. ``--speeds`` and ``--dt`` take lists;
``--converge`` also runs every speed at dt/2 and reports |e(dt) - e(dt/2)|.
"""

import argparse
import json
import math
import sys
import time

from yade import (
    O,  # noqa: F401  (yade -x has everything in builtins; explicit for readers)
    utils,
)
from yade.wrapper import (
    Bo1_Sphere_Aabb,
    ForceResetter,
    Ig2_Sphere_Sphere_ScGeom,
    InsertionSortCollider,
    InteractionLoop,
    Ip2_ViscElCapMat_ViscElCapMat_ViscElCapPhys,
    Law2_ScGeom_ViscElCapPhys_Basic,
    NewtonIntegrator,
    PyRunner,
    ViscElCapMat,
)

DEFAULTS = dict(
    R=1e-3, rho=2500.0,                       # sphere radius (m), density (kg/m3)
    tc=2e-5, en=0.9, et=1.0,                  # ViscElMat contact time (s), restitutions
    Vb=1e-11, gamma=0.072, theta=0.0,         # bridge volume (m3), N/m, contact angle (deg)
    dcap=2e-4,                                # bridge damping coefficient (N s/m)
    captype="Willett_numeric",
    gap=3e-4,                                 # start gap (m)
)


def build(p, v0, dt, partner, law):
    O.reset()
    O.dt = dt
    R = p["R"]
    if law == "viscelcap":
        mat = O.materials.append(ViscElCapMat(
            density=p["rho"], tc=p["tc"], en=p["en"], et=p["et"], frictionAngle=0.0,
            Capillar=p["capillar"], CapillarType=p["captype"], Vb=p["Vb"], gamma=p["gamma"],
            theta=p["theta"], dcap=p["dcap"]))
        ip2 = Ip2_ViscElCapMat_ViscElCapMat_ViscElCapPhys()
        law2 = Law2_ScGeom_ViscElCapPhys_Basic()
    else:
        from yade.wrapper import (
            FrictMat,
            Ip2_FrictMat_FrictMat_LubricationPhys,
            Law2_ScGeom_ImplicitLubricationPhys,
        )
        mat = O.materials.append(FrictMat(density=p["rho"], young=p["young"],
                                          poisson=p["poisson"], frictionAngle=0.0))
        ip2 = Ip2_FrictMat_FrictMat_LubricationPhys(eta=p["eta"], eps=p["eps"],
                                                    keps=p["keps"])
        law2 = Law2_ScGeom_ImplicitLubricationPhys(
            activateTangencialLubrication=False,
            activateTwistLubrication=False, activateRollLubrication=False,
            resolution=p["resolution"], theta=p["lub_theta"])
    # body 0: the partner at the origin; body 1: the moving sphere on its left
    b0 = utils.sphere((0.0, 0.0, 0.0), R, material=mat, fixed=(partner == "fixed"))
    b1 = utils.sphere((-(2.0 * R + p["gap"]), 0.0, 0.0), R, material=mat)
    O.bodies.append([b0, b1])
    if partner == "fixed":
        O.bodies[1].state.vel = (v0, 0.0, 0.0)
    else:
        O.bodies[1].state.vel = (0.5 * v0, 0.0, 0.0)
        O.bodies[0].state.vel = (-0.5 * v0, 0.0, 0.0)
    detect = p.get("detect", 1.0)
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=detect)]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=detect)],
                        [ip2], [law2]),
        NewtonIntegrator(damping=0.0, gravity=(0.0, 0.0, 0.0)),
        PyRunner(command="_record()", iterPeriod=1),
    ]


class Recorder:
    def __init__(self, R, g0, t_max, law):
        self.R, self.g0, self.t_max, self.law = R, g0, t_max, law
        self.t, self.g, self.v, self.bridge, self.touch, self.u = [], [], [], [], [], []
        self.done = False
        self.phys = None
        self.window = None        # record only while gap < window around the contact
        self.seen_touch = False

    def __call__(self):
        b0, b1 = O.bodies[0].state, O.bodies[1].state
        gap = (b0.pos[0] - b1.pos[0]) - 2.0 * self.R
        vrel = b1.vel[0] - b0.vel[0]          # approach speed (> 0 toward)
        has = O.interactions.has(0, 1) and O.interactions[0, 1].isReal
        if has and self.phys is None:
            self.phys = O.interactions[0, 1].phys
        # O.time is advanced after the engines run: the positions are those of time + dt
        self.t.append(O.time + O.dt)
        self.g.append(gap)
        self.v.append(vrel)
        self.bridge.append(bool(has))
        if self.law == "lubrication":
            ph = O.interactions[0, 1].phys if has else None
            self.touch.append(bool(ph is not None and ph.contact))
            self.u.append(float(ph.u) if ph is not None else float("nan"))
        else:
            self.touch.append(gap <= 0.0)
        if (vrel < 0.0 and gap >= self.g0) or O.time > self.t_max:
            self.done = True
            O.pause()
        elif self.window is not None:
            if self.touch[-1]:
                self.seen_touch = True
            elif self.seen_touch and vrel < 0.0 and gap > self.window:
                O.pause()


def crossing(t, g, k, level=0.0):
    """Time where g crosses ``level`` between samples k-1 and k (linear)."""
    t0, t1, g0, g1 = t[k - 1], t[k], g[k - 1], g[k]
    return t0 + (level - g0) * (t1 - t0) / (g1 - g0)


def analyse(rec, v0):
    """Contact: gap <= 0 (ViscElCap), or Yade's own flag phys.contact (u < 2 eps a) for
    the lubrication law, whose film gap u is not the geometric gap."""
    t, g, v, c = rec.t, rec.g, rec.v, rec.touch
    n = len(g)
    ks = next((k for k in range(1, n) if c[k] and not c[k - 1]), None)
    out = {"steps": n}
    if ks is None:
        out.update(outcome="no-contact", e=None, min_gap_m=min(g))
        return out
    ke = next((k for k in range(ks + 1, n) if c[k - 1] and not c[k]), None)
    out["max_overlap_m"] = -min(g)
    if rec.law == "lubrication":
        out["min_film_gap_m"] = min(x for x in rec.u if x == x)
        out["t_contact_start_s"] = t[ks]
        out["t_contact_end_s"] = t[ke] if ke is not None else None
    else:
        out["t_contact_start_s"] = crossing(t, g, ks)
        out["t_contact_end_s"] = crossing(t, g, ke) if ke is not None else None
    if ke is None:
        out.update(outcome="stuck", e=0.0)
        return out
    out["contact_duration_s"] = out["t_contact_end_s"] - out["t_contact_start_s"]
    # bridge rupture: first sample without the interaction after the contact
    kr = next((k for k in range(ke, n) if not rec.bridge[k]), None)
    if kr is not None and rec.law == "viscelcap":
        out["rupture_gap_m"] = [g[kr - 1], g[kr]]     # present at g[kr-1], gone at g[kr]
    kg = next((k for k in range(ke, n) if g[k] >= rec.g0 and v[k] < 0.0), None)
    if kg is None:
        out.update(outcome="captured", e=0.0, final_gap_m=g[-1], final_speed=v[-1])
        return out
    v_reb = -v[kg]
    out.update(outcome="rebound", e=v_reb / v0, v_rebound=v_reb, speed_at_contact=v[ks],
               t_back_at_start_gap_s=crossing(t, g, kg, rec.g0))
    return out


class ContactRecorder:
    """Per-step samples while the surfaces touch (switched on only around a contact)."""

    def __init__(self, R):
        self.R = R
        self.t, self.g, self.v = [], [], []
        self.touched = False

    def __call__(self):
        b0, b1 = O.bodies[0].state, O.bodies[1].state
        gap = (b0.pos[0] - b1.pos[0]) - 2.0 * self.R
        self.t.append(O.time + O.dt)
        self.g.append(gap)
        self.v.append(b1.vel[0] - b0.vel[0])
        if gap <= 0.0:
            self.touched = True
        elif self.touched:
            O.pause()


def _state(R):
    b0, b1 = O.bodies[0].state, O.bodies[1].state
    gap = (b0.pos[0] - b1.pos[0]) - 2.0 * R
    has = O.interactions.has(0, 1) and O.interactions[0, 1].isReal
    return gap, b1.vel[0] - b0.vel[0], has


def _chunk(R, p, gap, vrel, dt):
    """Steps for one bridge-phase chunk: at most 20 um of travel at the present speed (half
    the gap when approaching), and short enough that the pull (the present force, at least
    the capillary force at contact 2 pi R gamma, x3, x2 for a free pair) cannot bring the
    spheres back into contact within it. Each O.run(n, True) costs ~20 ms of waiting."""
    pull = max(abs(O.forces.f(1)[0]), 2.0 * math.pi * R * p["gamma"] * p["capillar"])
    acc = 6.0 * pull / O.bodies[1].state.mass + 1e-30
    reach = 2e-5 if vrel < 0.0 else min(2e-5, max(0.5 * gap, 1e-7))
    n_v = reach / (abs(vrel) * dt + 1e-30)
    n_a = math.sqrt(max(gap, 1e-9) / acc) / dt
    return int(max(20, min(200000, n_v, n_a)))


def run_fast(p, v0, dt, partner):
    """ViscElCap: free flight is run without Python in the loop (nothing acts before the
    first contact, nor after the rupture), per-step samples only during the contact, the
    bridge phase in chunks of at most 20 um of travel. e is the free-flight speed after the
    rupture, i.e. the speed at which the gap passes the start gap again."""
    import builtins
    build(p, v0, dt, partner, "viscelcap")
    R, g0 = p["R"], p["gap"]
    runner = O.engines[-1]
    runner.dead = True
    t_max = g0 / v0 * 25.0 + 1e-3
    w0 = time.time()
    pre = max(2e-6, 3.0 * v0 * dt)
    O.run(int((g0 - pre) / (v0 * dt)), True)
    out = {"contacts": 0}
    phys = None
    durations = []
    while True:
        # a contact, step by step
        rec = ContactRecorder(R)
        gap, vrel, _ = _state(R)                # seed: the state before the next step
        rec.t.append(O.time)
        rec.g.append(gap)
        rec.v.append(vrel)
        builtins._record = rec
        runner.dead = False
        while not (rec.touched and rec.g[-1] > 0.0) and O.time < t_max:
            O.run(20000, True)
        runner.dead = True
        if O.time >= t_max:
            out.update(outcome="stuck", e=0.0)
            break
        t, g = rec.t, rec.g
        ks = next(k for k in range(1, len(g)) if g[k] <= 0.0 < g[k - 1])
        ke = len(g) - 1
        if out["contacts"] == 0:
            out["t_contact_start_s"] = crossing(t, g, ks)
            out["speed_at_contact"] = rec.v[ks]
            out["max_overlap_m"] = -min(g)
        durations.append(crossing(t, g, ke) - crossing(t, g, ks))
        out["contacts"] += 1
        if O.interactions.has(0, 1):
            phys = O.interactions[0, 1].phys
        # the bridge, in chunks, until it ruptures, or the spheres turn back
        came_back = False
        while O.time < t_max:
            g_prev, v_prev, _ = _state(R)
            O.run(_chunk(R, p, g_prev, v_prev, dt), True)
            gap, vrel, has = _state(R)
            if gap <= 0.0:
                raise RuntimeError("a contact happened inside a bridge chunk")
            if not has and gap > 0.0:
                out["rupture_between_gaps_m"] = [g_prev, gap]
                break
            if vrel > 0.0:
                # turned back inside the bridge: the kinetic energy was zero below the
                # rupture distance and the laws only dissipate from there (the capillary force
                # depends on the gap alone): the bridge holds the pair for good
                came_back = True
                out["turning_gap_m"] = g_prev
                break
        if O.time >= t_max:
            out.update(outcome="captured", e=0.0, final_gap_m=_state(R)[0])
            break
        if came_back:
            out.update(outcome="captured", e=0.0)
            break
        gap, vrel, has = _state(R)
        v_reb = -vrel
        out.update(outcome="rebound" if out["contacts"] == 1 else "rebound-after-recontact",
                   e=v_reb / v0, v_rebound=v_reb,
                   t_back_at_start_gap_s=O.time + (g0 - gap) / v_reb if gap < g0 else None)
        break
    out["contact_duration_s"] = durations[0] if durations else None
    if len(durations) > 1:
        out["contact_durations_s"] = durations
    out.update(v0=v0, dt=dt, wall_s=time.time() - w0, steps=O.iter)
    if phys is not None:
        out["phys"] = {k: float(getattr(phys, k)) for k in
                       ("kn", "cn", "ks", "cs", "sCrit", "Vb", "gamma", "theta", "dcap")}
    return out


def run_one(p, v0, dt, partner, law):
    if law == "viscelcap":
        return run_fast(p, v0, dt, partner)
    # the lubrication law acts all the way: no free flight. Python records every step only
    # within `window` of the contact and on the last steps before the start gap; the rest
    # runs in chunks (each O.run(n, True) costs ~20 ms of waiting, a recorded step ~40 us).
    build(p, v0, dt, partner, law)
    R, g0 = p["R"], p["gap"]
    t_max = g0 / v0 * 25.0 + 1e-3
    rec = Recorder(R, g0, t_max, law)
    rec.window = window = 2e-5
    import builtins
    builtins._record = rec
    runner = O.engines[-1]
    w0 = time.time()
    runner.dead = True
    while O.time < t_max:                     # approach to the window, in chunks
        gap, vrel, _ = _state(R)
        n = int((gap - window) / (abs(vrel) * dt + 1e-30)) - 2
        if n < 10:
            break
        O.run(min(n, 400000), True)
    runner.dead = False                       # the contact, step by step
    while not rec.done and not (rec.seen_touch and not rec.touch[-1] and rec.v[-1] < 0.0
                                and rec.g[-1] > window):
        O.run(400000, True)
    runner.dead = True
    while not rec.done and O.time < t_max:    # back to the start gap, in chunks
        gap, vrel, _ = _state(R)
        n = int((g0 - gap) / (abs(vrel) * dt + 1e-30)) - 3
        if vrel > 0.0 or n < 10:
            break
        O.run(min(n, 400000), True)
    rec.window = None
    runner.dead = False
    while not rec.done:
        O.run(400000, True)
    res = analyse(rec, v0)
    res.update(v0=v0, dt=dt, wall_s=time.time() - w0)
    ph = rec.phys
    if ph is not None:
        res["phys"] = {k: float(getattr(ph, k)) for k in
                       ("kn", "cn", "ks", "cs", "sCrit", "Vb", "gamma", "theta", "dcap")
                       if hasattr(ph, k)} if law == "viscelcap" else {
            k: float(getattr(ph, k)) for k in ("eta", "eps", "kn", "keps", "kno", "nun", "a")
            if hasattr(ph, k)}
    return res


def _version():
    try:
        import yade.config
        return str(yade.config.version)
    except Exception:  # noqa: BLE001
        return ""


def main(argv):
    ap = argparse.ArgumentParser()
    ap.add_argument("--speeds", default="0.1,0.2,0.5,1.0")
    ap.add_argument("--dt", type=float, default=6.25e-9)
    ap.add_argument("--converge", action="store_true", help="also run at dt/2")
    ap.add_argument("--partner", choices=("fixed", "pair"), default="fixed")
    ap.add_argument("--law", choices=("viscelcap", "lubrication"), default="viscelcap")
    ap.add_argument("--dry", action="store_true", help="Capillar=False (the dry contact)")
    ap.add_argument("--captype", default=DEFAULTS["captype"])
    ap.add_argument("--theta", type=float, default=DEFAULTS["theta"])
    ap.add_argument("--dcap", type=float, default=DEFAULTS["dcap"])
    ap.add_argument("--gap", type=float, default=DEFAULTS["gap"])
    ap.add_argument("--detect", type=float, default=1.0,
                    help="aabbEnlargeFactor = interactionDetectionFactor")
    # lubrication law parameters
    ap.add_argument("--eta", type=float, default=1e-3)
    ap.add_argument("--eps", type=float, default=1e-3)
    ap.add_argument("--keps", type=float, default=1.0)
    ap.add_argument("--young", type=float, default=5e9)
    ap.add_argument("--poisson", type=float, default=0.3)
    ap.add_argument("--resolution", type=int, default=0)
    ap.add_argument("--lub-theta", type=float, default=0.55)
    ap.add_argument("--out", default=None)
    a = ap.parse_args(argv)
    p = dict(DEFAULTS)
    p.update(capillar=not a.dry, captype=a.captype, theta=a.theta, dcap=a.dcap, gap=a.gap,
             detect=a.detect, eta=a.eta, eps=a.eps, keps=a.keps, young=a.young,
             poisson=a.poisson, resolution=a.resolution, lub_theta=a.lub_theta)
    speeds = [float(s) for s in a.speeds.split(",")]
    runs = []
    for v0 in speeds:
        r = run_one(p, v0, a.dt, a.partner, a.law)
        if a.converge:
            r2 = run_one(p, v0, 0.5 * a.dt, a.partner, a.law)
            r["half_dt"] = {k: r2.get(k) for k in ("e", "contact_duration_s", "outcome",
                                                   "rupture_gap_m", "wall_s", "steps")}
            if r.get("e") is not None and r2.get("e") is not None:
                r["e_change_half_dt"] = abs(r["e"] - r2["e"])
        runs.append(r)
    mass = 4.0 / 3.0 * math.pi * p["R"] ** 3 * p["rho"]
    doc = {"code": "yade", "version": _version(),
           "law": a.law, "partner": a.partner, "params": p, "mass_kg": mass,
           "dt": a.dt, "runs": runs}
    txt = json.dumps(doc)
    if a.out:
        with open(a.out, "w") as f:
            f.write(json.dumps(doc, indent=1) + "\n")
    print(txt)


main(sys.argv[1:])
sys.exit(0)
