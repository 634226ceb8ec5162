"""Reference values of problems/pinned_arch_full.toml, independent of cosserat.

The pinned-pinned circular arch (span 2l, l = 1, B = 1, kappa0 = Theta = 0.5)
under a dead crown load P (down = +x): the planar elastica

    x' = sin t,  z' = cos t,  t' = Theta + m,  m' = -(n_x cos t - n_z sin t),

n = R + P e_x on (0, 1), n = R on (1, 2), shot from t(0) = t0, m(0) = 0 (the
hinge) with its variational equations (scipy DOP853, rtol = atol = 1e-13) to
x(2) = 0, z(2) = 2 sin(Theta)/Theta, m(2) = 0 (the pin).

* The asymmetric branch point: where the load-control Jacobian
  d(x, z, m)(2)/d(t0, Rx, Rz) is singular along the symmetric branch
  (secant on its determinant; +- 3e-9, the determinant's noise over its
  slope).
* The symmetric fold: the crown's deflection d = x(1) prescribed, P an
  unknown; the fold is where dP/dd = 0 (secant on the exact derivative;
  +- 1e-10).

Run: python3 scripts/pinned_arch_reference.py (about a minute).
"""
import numpy as np
from scipy.integrate import solve_ivp

THETA = 0.5
CHORD = 2 * np.sin(THETA) / THETA
TOL = 1e-13


def rhs(s, y, n, dn):
    """The state (x, z, t, m) and its sensitivities to (t0, Rx, Rz, P)."""
    _, _, t, m = y[:4]
    sens = y[4:].reshape(4, 4)
    c, si = np.cos(t), np.sin(t)
    f = [si, c, THETA + m, -(c * n[0] - si * n[1])]
    a = np.array([[0, 0, c, 0], [0, 0, -si, 0], [0, 0, 0, 1],
                  [0, 0, si * n[0] + c * n[1], 0]])
    force = np.array([[0, 0], [0, 0], [0, 0], [-c, si]])
    return np.concatenate([f, (a @ sens + force @ dn).ravel()])


def shoot(v):
    """States at the crown and the far end for v = (t0, Rx, Rz, P)."""
    t0, rx, rz, p = v
    y = np.zeros(20)
    y[2] = t0
    y[4 + 2 * 4 + 0] = 1.0  # dt(0)/dt0
    before = np.array([[0, 1, 0, 1], [0, 0, 1, 0]], float)
    after = np.array([[0, 1, 0, 0], [0, 0, 1, 0]], float)
    crown = solve_ivp(rhs, (0, 1), y, args=(np.array([rx + p, rz]), before),
                      method="DOP853", rtol=TOL, atol=TOL).y[:, -1]
    end = solve_ivp(rhs, (1, 2), crown, args=(np.array([rx, rz]), after),
                    method="DOP853", rtol=TOL, atol=TOL).y[:, -1]
    return crown, end


def end_conditions(v):
    crown, end = shoot(v)
    r = np.array([end[0], end[1] - CHORD, end[3]])
    jac = end[4:].reshape(4, 4)[[0, 1, 3], :]
    return r, jac, crown


def load_control(v, p):
    """Newton in (t0, Rx, Rz) at the load p; the determinant there."""
    v = np.array([*v[:3], p])
    for _ in range(20):
        r, jac, _ = end_conditions(v)
        dv = np.linalg.solve(jac[:, :3], -r)
        v[:3] += dv
        if np.abs(dv).max() < 1e-13:
            break
    _, jac, _ = end_conditions(v)
    return v, np.linalg.det(jac[:, :3])


def displacement_control(v, d):
    """Newton in (t0, Rx, Rz, P) at the crown's deflection d; dP/dd."""
    for _ in range(20):
        r, jac, crown = end_conditions(v)
        full_r = np.append(r, crown[0] - d)
        full_j = np.vstack([jac, crown[4:].reshape(4, 4)[0:1, :]])
        dv = np.linalg.solve(full_j, -full_r)
        v = v + dv
        if np.abs(dv).max() < 1e-12:
            break
    r, jac, crown = end_conditions(v)
    full_j = np.vstack([jac, crown[4:].reshape(4, 4)[0:1, :]])
    return v, np.linalg.solve(full_j, np.array([0, 0, 0, 1.0]))[3]


def secant(f, a, b, steps=12):
    fa, fb = f(a), f(b)
    for _ in range(steps):
        if fb == fa:
            break
        a, fa, b = b, fb, b - fb * (b - a) / (fb - fa)
        fb = f(b)
    return b


def main():
    v = np.array([-THETA, 0.0, 0.0, 0.0])
    for p in np.linspace(0.0, 5.9, 25):
        v, _ = load_control(v, p)
    state = {"v": v}

    def det(p):
        state["v"], d = load_control(state["v"], p)
        return d

    print("branch point P =", repr(secant(det, 5.9, 5.93, steps=5)))
    v = np.array([-THETA, 0.0, 0.0, 0.0])
    rest = shoot(v)[0][0]
    for d in np.linspace(rest, -0.14, 8):
        v, _ = displacement_control(v, d)
    state["v"] = v

    def slope(d):
        state["v"], s = displacement_control(state["v"], d)
        return s

    secant(slope, -0.14, -0.12)
    print("fold P =", repr(state["v"][3]))


if __name__ == "__main__":
    main()
