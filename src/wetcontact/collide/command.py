"""``wetcontact collide CASE.toml``: one wet impact from the command line."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any


def add_parser(sub: Any, path_arg: Any) -> None:
    """Add the ``collide`` subcommand to the ``wetcontact`` parser's subparsers."""
    c = sub.add_parser("collide", help="one wet impact: restitution, stick or rebound",
                       description="Integrate one wet impact (penetration, solid contact, "
                       "emergence, bridge) with the case's [impact], [solid], [contact] "
                       "and [phases] tables and print its restitution, outcome, phases and "
                       "energy budget.")
    c.add_argument("case", type=path_arg, help="TOML case file with [impact] and [solid]")
    c.add_argument("--viscous", default=None, metavar="MODEL", help="viscous force model "
                   "(wetcontact models), or none; default: the calibrated closure where it "
                   "applies, the exact or published closure elsewhere")
    c.add_argument("--capillary", default=None, metavar="MODEL", help="capillary force model, "
                   "or none; default: calibrated-capillary where it applies, meniscus "
                   "elsewhere")
    c.add_argument("--tol", type=float, default=None, help="absolute tolerance on e: the "
                   "cheapest force models whose measured restitution error meets it (not with "
                   "--viscous or --capillary)")
    c.add_argument("--rtol", type=float, default=None, help="integrator tolerance (default "
                   "1e-10)")
    c.add_argument("--json", action="store_true", help="print one JSON object")
    c.add_argument("--trajectory", type=path_arg, default=None, metavar="FILE.csv",
                   help="write time, gap, velocity and forces as CSV")


def run(args: argparse.Namespace) -> int:
    """Run the ``collide`` subcommand; returns the exit code."""
    from wetcontact.collide import collide, load_collision_case
    from wetcontact.errors import InputError
    from wetcontact.fileio import writable_file
    from wetcontact.models import load_all

    if args.trajectory is not None:  # before any work
        writable_file(args.trajectory, "--trajectory", make_folders=False)
    rtol = 1e-10 if args.rtol is None else args.rtol
    if not 1e-14 <= rtol <= 1e-3:
        raise InputError(f"--rtol {rtol!r}; allowed: a number in [1e-14, 1e-3]")
    case = load_collision_case(args.case)
    load_all()
    res = collide(case, viscous=args.viscous, capillary=args.capillary, rtol=rtol,
                  trajectory=args.trajectory is not None, tol=args.tol)
    if args.trajectory is not None:
        res.write_trajectory(args.trajectory)
    if args.json:
        sys.stdout.write(json.dumps(res.to_json_dict()) + "\n")
        return 0
    out = [f"{res.case}: {res.outcome}, e = {res.restitution:.6g} (St = "
           f"{res.stokes_number:.4g}; viscous {res.models['viscous']}, capillary "
           f"{res.models['capillary']})"]
    if res.contact_velocity is not None:
        out.append(f"  contact speed {res.contact_velocity:.6g} m/s"
                   + (f", rebound speed {res.rebound_velocity:.6g} m/s"
                      if res.rebound_velocity is not None else ""))
    for p in res.phases:
        out.append(f"  {p.name:<12} {p.start:.6e} s .. {p.end:.6e} s")
    e = res.energy
    out.append("  energy (J): " + ", ".join(f"{k} {v:.4e}" for k, v in e.items()))
    if "tolerance" in res.models:
        out.append(f"  --tol: {res.models['tolerance']['reason']}")
    out.extend(f"  outside validity: {n}" for n in res.validity)
    sys.stdout.write("\n".join(out) + "\n")
    return 0
