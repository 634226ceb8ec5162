"""cosserat.solve against the elastica's published values, and the
problem as a file, a dict and overrides."""

import math
import tomllib

import numpy as np
import pytest

import cosserat

# Mattiasson (1981), Table 1, k = F L²/B2 = 1: tip deflection v/L = 0.30172,
# shortening u/L = 0.05643 (so z = 1 − u/L), tip rotation 0.46135 rad.
MATTIASSON_K1 = {"x": 0.30172, "z": 1.0 - 0.05643, "angle": 0.46135}
# The table gives five digits: half a unit of the last one, plus the
# solver's error (far smaller).
FIVE_DIGITS = 1e-5


@pytest.mark.parametrize("method", ["shooting", "multiple-shooting", "collocation"])
def test_cantilever_tip_matches_mattiasson(problem_path, method):
    eq = cosserat.solve(
        problem_path("cantilever_tip_load"),
        **{"loads.tip_force": [1.0, 0.0, 0.0], "solver.method": method},
    )
    x, _, z = eq.tip
    angle = math.atan2(eq.d3[-1, 0], eq.d3[-1, 2])
    assert eq.method == method
    assert abs(x - MATTIASSON_K1["x"]) <= FIVE_DIGITS
    assert abs(z - MATTIASSON_K1["z"]) <= FIVE_DIGITS
    assert abs(angle - MATTIASSON_K1["angle"]) <= FIVE_DIGITS
    assert eq.verdict == "stable"


def test_arrays_describe_a_rod(problem_path):
    eq = cosserat.solve(problem_path("cantilever_tip_load"))
    n = len(eq.s)
    assert eq.s[0] == 0.0 and eq.s[-1] == pytest.approx(1.0)
    for name in ("position", "d1", "d2", "d3", "curvature", "moment", "force"):
        assert getattr(eq, name).shape == (n, 3), name
    # The directors are orthonormal and right-handed, and d3 is the
    # tangent dr/ds of this unshearable rod (central differences).
    frame = np.stack([eq.d1, eq.d2, eq.d3], axis=1)
    gram = np.einsum("nij,nkj->nik", frame, frame)
    assert np.abs(gram - np.eye(3)).max() < 1e-9
    assert np.abs(np.cross(eq.d1, eq.d2) - eq.d3).max() < 1e-9
    tangent = np.gradient(eq.position, eq.s, axis=0, edge_order=2)
    assert np.abs(tangent - eq.d3).max() < 1e-3
    # The internal force balances the tip load everywhere (no other load).
    assert np.allclose(eq.force, [3.0, 0.0, 0.0], atol=1e-9)
    assert eq.tip == pytest.approx(eq.position[-1])
    assert eq.residual <= 1e-8


def test_a_dict_problem_is_the_file_problem(problem_path):
    path = problem_path("cantilever_tip_load")
    from_file = cosserat.solve(str(path))
    with open(path, "rb") as f:
        from_dict = cosserat.solve(tomllib.load(f))
    for name in ("s", "position", "d1", "d2", "d3", "curvature", "moment", "force"):
        assert np.array_equal(getattr(from_file, name), getattr(from_dict, name)), name


def test_overrides_are_the_set_keys(problem_path):
    path = problem_path("cantilever_tip_load")
    with open(path, "rb") as f:
        edited = tomllib.load(f)
    edited["loads"]["tip_force"][0] = 1.5
    edited["solver"]["method"] = "collocation"
    by_dict = cosserat.solve(edited)
    by_override = cosserat.solve(
        path, **{"loads.tip_force[0]": 1.5, "solver.method": "collocation"}
    )
    assert by_override.method == "collocation"
    assert np.array_equal(by_dict.position, by_override.position)
    # NumPy values are TOML values too.
    by_numpy = cosserat.solve(
        path,
        **{"loads.tip_force": np.array([1.5, 0.0, 0.0]), "solver.method": "collocation"},
    )
    assert np.array_equal(by_numpy.position, by_override.position)


def test_stability_of_the_cantilever_is_stable(problem_path):
    st = cosserat.stability(problem_path("cantilever_tip_load"))
    assert st.kind == "equilibrium"
    assert st.verdict == "stable" and st.morse_index == 0
    for values in st.eigenvalues.values():
        assert (values > 0).all()


def test_euler_column_critical_load(problem_path):
    # Euler (1744): the clamped-free column buckles at F L²/B = π²/4.
    st = cosserat.stability(problem_path("euler_column"))
    assert st.kind == "fixed_shape" and st.verdict == "critical"
    euler = math.pi**2 / 4
    assert abs(st.gamma - euler) <= 1e-8 * euler
    # B1 = B2: both bending blocks buckle at the same load.
    for factor in st.block_load_factors.values():
        assert abs(factor - euler) <= 1e-8 * euler
