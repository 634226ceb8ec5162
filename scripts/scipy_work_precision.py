#!/usr/bin/env python3
"""scipy's solve_bvp on the work-precision chart's planar cantilevers.

The same scenes as `cosserat bench work-precision` (crates/cosserat-cli/src/bench.rs):
a unit cantilever (L = 1, B = 1) clamped along z, a tip force k = F L²/B along x,
k = 3 and 10. With θ the angle of the tangent from the clamp's,

    x' = sin θ,  z' = cos θ,  θ' = κ,  κ' = −k cos θ,
    x(0) = z(0) = θ(0) = 0,  κ(1) = 0,

solved by scipy.integrate.solve_bvp (4th-order collocation with residual control) with
its analytic Jacobians, from the linear-theory shape θ = k(s − s²/2) on 11 nodes, for
tol = 1e-2 … 1e-10. Error: the max-norm of the tip's (x, z) against the closed form of
Bisshopp & Drucker (Q. Appl. Math. 3, 1945), evaluated here with scipy.special's elliptic
integrals (independent of the Rust one): with the tip angle φ0, p² = (1 + sin φ0)/2,
sin θ0 = 1/(p√2), √k = K(p) − F(θ0, p); x = 1 − 2(E(p) − E(θ0, p))/√k, z = √(2 sin φ0/k).
Time: the median wall time of repeated solves in this process (timeit), as cosserat's
in-process medians.

Writes rows in work_precision.csv's format (method "scipy solve_bvp", mesh_size = the
final number of nodes, newton_steps = "0": solve_bvp does not report them), so that
`cosserat bench work-precision --redraw work_precision.csv --redraw scipy.csv` draws both.

Usage: python3 scripts/scipy_work_precision.py OUTPUT.csv
"""
import math
import sys
import timeit

import numpy as np
from scipy.integrate import solve_bvp
from scipy.optimize import brentq
from scipy.special import ellipe, ellipeinc, ellipk, ellipkinc


def closed_form(k):
    """Tip (x, z) of Bisshopp & Drucker's cantilever; scipy's m is the parameter p²."""
    sqrt_k = math.sqrt(k)

    def theta0(p):
        return math.asin(1.0 / (p * math.sqrt(2.0)))

    def lhs(p):
        return ellipk(p * p) - ellipkinc(theta0(p), p * p) - sqrt_k

    p = brentq(lhs, math.sqrt(0.5) * (1 + 1e-15), 1.0 - 1e-15, xtol=1e-16, rtol=1e-15, maxiter=500)
    t0 = theta0(p)
    sin_phi0 = 2.0 * p * p - 1.0
    x = 1.0 - 2.0 * (ellipe(p * p) - ellipeinc(t0, p * p)) / sqrt_k
    z = math.sqrt(2.0 * sin_phi0 / k)
    return x, z


def solve(k, tol):
    def fun(s, y):
        return np.vstack((np.sin(y[2]), np.cos(y[2]), y[3], -k * np.cos(y[2])))

    def fun_jac(s, y):
        m = y.shape[1]
        j = np.zeros((4, 4, m))
        j[0, 2] = np.cos(y[2])
        j[1, 2] = -np.sin(y[2])
        j[2, 3] = 1.0
        j[3, 2] = k * np.sin(y[2])
        return j

    def bc(ya, yb):
        return np.array([ya[0], ya[1], ya[2], yb[3]])

    def bc_jac(ya, yb):
        a = np.zeros((4, 4))
        b = np.zeros((4, 4))
        a[0, 0] = a[1, 1] = a[2, 2] = 1.0
        b[3, 3] = 1.0
        return a, b

    s = np.linspace(0.0, 1.0, 11)
    theta = k * (s - 0.5 * s * s)
    y = np.vstack((k * (s * s / 2 - s**3 / 6), s, theta, k * (1 - s)))
    return solve_bvp(fun, bc, s, y, fun_jac=fun_jac, bc_jac=bc_jac, tol=tol,
                     bc_tol=tol, max_nodes=200000)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__.strip().splitlines()[-1])
    rows = ["scene,method,parameter,tip_error,time_s,newton_steps,mesh_size"]
    for k in (3.0, 10.0):
        x_ref, z_ref = closed_form(k)
        for e in range(2, 11):
            tol = 10.0 ** -e
            sol = solve(k, tol)
            if not sol.success:
                print(f"k = {k:g}, tol = {tol:.0e}: {sol.message}", file=sys.stderr)
                continue
            tip = sol.y[:, -1]
            error = max(abs(tip[0] - x_ref), abs(tip[1] - z_ref))
            timer = timeit.Timer(lambda: solve(k, tol))
            number, _ = timer.autorange()
            runs = [t / number for t in timer.repeat(repeat=7, number=number)]
            time = sorted(runs)[len(runs) // 2]
            rows.append(f"planar cantilever k = {k:g},scipy solve_bvp,{tol:e},{error:e},{time:e},0,{sol.x.size}")
            print(f"k = {k:g}, tol = {tol:.0e}: tip error {error:.2e}, {time * 1e3:.3f} ms, {sol.x.size} nodes")
    with open(sys.argv[1], "w", encoding="utf-8") as f:
        f.write("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
