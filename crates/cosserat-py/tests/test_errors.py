"""Failures are Python exceptions naming what is wrong, never a crash."""

import tomllib

import pytest

import cosserat


def test_a_bad_value_names_its_field(problem_path):
    with pytest.raises(cosserat.ProblemError) as caught:
        cosserat.solve(problem_path("cantilever_tip_load"), **{"energy.stiffness": [-1, 1, 1]})
    e = caught.value
    assert isinstance(e, cosserat.CosseratError)
    assert e.field == "energy.stiffness[0]"
    assert "positive" in e.message
    assert str(e).startswith("energy.stiffness[0]: ")


def test_a_dict_error_names_the_same_field(problem_path):
    with open(problem_path("cantilever_tip_load"), "rb") as f:
        problem = tomllib.load(f)
    problem["energy"]["stiffness"] = [-1.0, 1.0, 1.0]
    with pytest.raises(cosserat.ProblemError) as caught:
        cosserat.solve(problem)
    assert caught.value.field == "energy.stiffness[0]"


def test_an_unknown_key_is_refused(problem_path):
    with open(problem_path("cantilever_tip_load"), "rb") as f:
        problem = tomllib.load(f)
    problem["rod"]["lenght"] = 2.0
    with pytest.raises(cosserat.ProblemError, match="lenght"):
        cosserat.solve(problem)


def test_an_override_that_cannot_be_set_names_its_key(problem_path):
    with pytest.raises(cosserat.ProblemError) as caught:
        cosserat.solve(problem_path("cantilever_tip_load"), **{"loads.tip_force[7]": 1.0})
    assert caught.value.field == "loads.tip_force[7]"
    with pytest.raises(cosserat.ProblemError) as caught:
        cosserat.solve(problem_path("cantilever_tip_load"), **{"solver.method": "bogus"})
    assert caught.value.field == "solver.method"


def test_a_value_that_is_no_toml_is_refused(problem_path):
    with pytest.raises(cosserat.ProblemError) as caught:
        cosserat.solve(problem_path("cantilever_tip_load"), **{"rod.length": object()})
    assert caught.value.field == "rod.length"


def test_a_missing_file_or_a_wrong_type(tmp_path):
    with pytest.raises(cosserat.ProblemError, match="cannot read") as caught:
        cosserat.solve(tmp_path / "absent.toml")
    assert caught.value.field is None
    with pytest.raises(cosserat.ProblemError, match="problem"):
        cosserat.solve(42)


def test_a_command_for_another_table(problem_path):
    with pytest.raises(cosserat.ProblemError) as caught:
        cosserat.solve(problem_path("euler_column"))
    assert caught.value.field == "shape"
    with pytest.raises(cosserat.ProblemError) as caught:
        cosserat.continuation(problem_path("cantilever_tip_load"))
    assert caught.value.field == "continuation"
    with pytest.raises(cosserat.ProblemError) as caught:
        cosserat.optimize(problem_path("cantilever_tip_load"))
    assert caught.value.field == "arm"


def test_no_equilibrium_is_a_solve_error(problem_path):
    # One Newton step cannot reach a large deflection from the straight
    # guess, and no load ramp is allowed to help.
    with pytest.raises(cosserat.SolveError, match="what to do"):
        cosserat.solve(
            problem_path("cantilever_tip_load"),
            **{"solver.max_iterations": 1, "solver.strategy": "direct"},
        )


def test_to_hdf5_claims_its_output(problem_path, tmp_path):
    path = problem_path("cantilever_tip_load")
    eq = cosserat.solve(path)
    out = tmp_path / "eq.h5"
    eq.to_hdf5(out)
    with pytest.raises(cosserat.OutputError):
        eq.to_hdf5(out)
    eq.to_hdf5(out, force=True)
    before = path.read_bytes()
    with pytest.raises(cosserat.OutputError):
        eq.to_hdf5(path, force=True)
    assert path.read_bytes() == before
    with pytest.raises(cosserat.OutputError):
        eq.to_hdf5(tmp_path, force=True)
