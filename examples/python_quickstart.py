# %% [markdown]
# # cosserat from Python: solve, continue, plot
#
# A notebook in the percent format (`# %%` cells): open it in Jupyter
# (with jupytext), VS Code or Spyder, or run it as a script. It needs
# `pip install ./crates/cosserat-py matplotlib`; run from the repository
# root (or anywhere: it finds problems/ next to this file), it saves its
# figures as PNG files in the current directory.

# %%
from pathlib import Path

import matplotlib

if "__file__" in globals():  # run as a script (as the tests do): no screen
    matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import cosserat

HERE = Path(__file__).resolve().parent if "__file__" in globals() else Path.cwd()
PROBLEMS = (HERE.parent if (HERE.parent / "problems").is_dir() else HERE) / "problems"

# %% [markdown]
# ## One equilibrium
# The large-deflection cantilever of problems/cantilever_tip_load.toml
# (x = e1 points down, z = e3 along the clamp), under three tip loads
# k = F L²/B2 set as the command's `--set` keys.

# %%
fig, ax = plt.subplots(figsize=(5, 4))
for k in (1.0, 3.0, 10.0):
    eq = cosserat.solve(PROBLEMS / "cantilever_tip_load.toml", **{"loads.tip_force": [k, 0.0, 0.0]})
    print(f"k = {k:4}: tip {eq.tip.round(5)}, {eq.method}, residual {eq.residual:.1e}, {eq.verdict}")
    ax.plot(eq.position[:, 2], -eq.position[:, 0], label=f"k = {k:g}")
ax.set_xlabel("z (along the clamp)")
ax.set_ylabel("−x (up)")
ax.set_aspect("equal")
ax.legend()
fig.savefig("cantilever_shapes.png", dpi=120)

# %% [markdown]
# ## A bifurcation diagram
# Euler's column (problems/euler_column.toml): the straight column loses
# stability at F L²/B = π²/4, where the buckled branches start.

# %%
diagram = cosserat.continuation(PROBLEMS / "euler_column.toml")
print(diagram)
for point in diagram.special_points:
    print(f"  {point.kind} at {point.parameter:.10f} ({point.block}); π²/4 = {np.pi**2 / 4:.10f}")

fig, ax = plt.subplots(figsize=(5, 4))
for i, branch in enumerate(diagram.branches):
    load, tip_x = branch.parameter, branch.measures["tip_x"]
    stable = np.where(branch.stable, tip_x, np.nan)
    unstable = np.where(branch.stable, np.nan, tip_x)
    ax.plot(load, stable, "-", color=f"C{i}", label=f"branch {i}")
    ax.plot(load, unstable, "--", color=f"C{i}")
for point in diagram.special_points:
    ax.plot(point.parameter, point.tip[0], "ko")
ax.set_xlabel(diagram.parameter_name + " (F L²/B)")
ax.set_ylabel("tip x (solid: stable, dashed: unstable)")
ax.legend(loc="lower left")
fig.savefig("euler_column_diagram.png", dpi=120)

# %% [markdown]
# ## Keep the results
# The same HDF5 files as `cosserat continue -o` (readable by
# `cosserat plot` and h5py; docs/hdf5-schema.md lists their datasets).

# %%
diagram.to_hdf5("euler_column.h5", force=True)
