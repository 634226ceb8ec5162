"""`.to_hdf5` writes the command's files: every dataset the schema
(docs/hdf5-schema.md) lists, read back with h5py."""

import h5py
import numpy as np

import cosserat
from conftest import schema_paths


def test_an_equilibrium_file(problem_path, tmp_path):
    eq = cosserat.solve(problem_path("cantilever_tip_load"))
    out = tmp_path / "eq.h5"
    eq.to_hdf5(out)
    with h5py.File(out, "r") as f:
        for path in schema_paths("`cosserat solve -o` (an equilibrium)"):
            assert path in f, path
        assert np.array_equal(f["/solution/position"][()], eq.position)
        assert np.array_equal(f["/solution/s"][()], eq.s)


def test_a_stability_file(problem_path, tmp_path):
    st = cosserat.stability(problem_path("cantilever_tip_load"))
    out = tmp_path / "st.h5"
    st.to_hdf5(out)
    with h5py.File(out, "r") as f:
        for path in schema_paths("`cosserat stability -o` (an equilibrium and its spectrum)"):
            assert path in f, path
        for block, values in st.eigenvalues.items():
            assert np.array_equal(f[f"/stability/{block}/eigenvalues"][()], values)


def test_a_fixed_shape_file(problem_path, tmp_path):
    st = cosserat.stability(problem_path("euler_column"))
    out = tmp_path / "critical.h5"
    st.to_hdf5(out)
    title = "`cosserat stability -o` on a `[shape]` problem (a fixed shape's critical load)"
    with h5py.File(out, "r") as f:
        for path in schema_paths(title):
            assert path in f, path
        assert f["/stability/load_factor"][()] == st.load_factor


def test_a_diagram_file(problem_path, tmp_path):
    d = cosserat.continuation(problem_path("euler_column"))
    out = tmp_path / "column.h5"
    d.to_hdf5(out)
    with h5py.File(out, "r") as f:
        for i, branch in enumerate(d.branches):
            assert np.array_equal(f[f"/branches/{i}/parameter"][()], branch.parameter)
            assert np.array_equal(f[f"/branches/{i}/tip_position"][()], branch.tip)
        located = f["/special_points/parameter"][()]
        assert np.array_equal(located, [s.parameter for s in d.special_points])
