"""cosserat.continuation of Euler's column against the closed forms."""

import math

import numpy as np

import cosserat


def complete_elliptic_k(k):
    """K(k) by the arithmetic-geometric mean: π / (2 AGM(1, √(1 − k²)))."""
    a, b = 1.0, math.sqrt(1.0 - k * k)
    for _ in range(40):  # quadratic convergence: exact to rounding long before
        a, b = (a + b) / 2, math.sqrt(a * b)
    return math.pi / (2 * a)


def test_euler_column_branch_point_and_elastica(problem_path):
    d = cosserat.continuation(problem_path("euler_column"))
    assert d.parameter_name == "load_scale"
    assert d.stop_reason == "completed"
    euler = math.pi**2 / 4
    in_plane = [
        s for s in d.special_points if s.kind == "branch_point" and s.block == "in_plane"
    ]
    assert len(in_plane) == 1
    bp = in_plane[0]
    # Euler (1744): the clamped-free column buckles at F L²/B = π²/4.
    assert abs(bp.parameter - euler) <= 1e-8 * euler
    assert bp.symmetry_breaking and len(bp.children) == 2
    # The straight branch is stable below π²/4 and unstable above it.
    straight = d.branches[0]
    p, stable = straight.parameter, straight.stable
    assert stable[p < euler * 0.99].all() and not stable[p > euler * 1.01].any()
    assert straight.eigenvalues.shape == (len(straight), len(d.eigenvalue_names))
    # The buckled elastica: F L²/B = K(k)², k = sin(α/2) with α the tip
    # angle (Timoshenko & Gere, Sec. 2.7).
    for child in bp.children:
        branch = d.branches[child]
        assert branch.parent is not None
        for load, angle in list(zip(branch.parameter, branch.measures["tip_angle"]))[1:]:
            exact = complete_elliptic_k(math.sin(abs(angle) / 2)) ** 2
            assert abs(load - exact) <= 1e-8 * exact, (angle, load, exact)
        assert np.array_equal(branch.measures["tip_x"], branch.tip[:, 0])
