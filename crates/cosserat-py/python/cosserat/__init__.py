"""Statics and stability of slender elastic rods, from Python.

The library behind the ``cosserat`` command, on the same problems: a
problem file's path, or a dict with the problem file's tables (see
docs/problem-files.md), and keyword overrides that are the command's
``--set`` keys::

    import cosserat
    eq = cosserat.solve("problems/cantilever_tip_load.toml",
                        **{"loads.tip_force": [1.0, 0.0, 0.0]})
    eq.position[-1]                       # the tip, a NumPy array
    d = cosserat.continuation("problems/euler_column.toml")
    d.special_points[0].parameter         # pi**2/4 for Euler's column
    d.to_hdf5("column.h5", force=True)    # the file `cosserat continue` writes

Functions: :func:`solve` (an :class:`Equilibrium`), :func:`stability`
(a :class:`Stability`), :func:`continuation` (a :class:`Diagram` of
:class:`Branch` es and :class:`SpecialPoint` s), :func:`optimize` (an
:class:`Arm`). Failures raise :class:`ProblemError` (``.field`` is the key
at fault), :class:`SolveError` (no result) or :class:`OutputError`, all
:class:`CosseratError` s.
"""

from ._cosserat import (
    REACH_TOLERANCE,
    Arm,
    Branch,
    CosseratError,
    Diagram,
    Equilibrium,
    OutputError,
    ProblemError,
    SolveError,
    SpecialPoint,
    Stability,
    continuation,
    optimize,
    solve,
    stability,
)

__all__ = [
    "REACH_TOLERANCE",
    "Arm",
    "Branch",
    "CosseratError",
    "Diagram",
    "Equilibrium",
    "OutputError",
    "ProblemError",
    "SolveError",
    "SpecialPoint",
    "Stability",
    "continuation",
    "optimize",
    "solve",
    "stability",
]
