"""Reads the files of `cosserat export` back with VTK's own readers and
compares them with the HDF5 result file read by h5py: nothing of cosserat's
code is on this side. Used by tests/export.rs.

    read_back.py vtp  OUT.vtp  FILE.h5 LENGTH
    read_back.py pvd  OUT.pvd  FILE.h5 LENGTH [BRANCH]
    read_back.py xmf  OUT.xmf  FILE.h5 LENGTH [BRANCH]

LENGTH is the rod length from the problem file (s must span [0, LENGTH]);
BRANCH the exported branch of a diagram (all branches without it).
Exits 0 when every check passes, 1 with the failed check on stderr.
"""
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

# Body-frame arrays are exported under names that say so.
EQUILIBRIUM = {"s": "s", "d1": "d1", "d2": "d2", "d3": "d3",
               "curvature_body": "curvature", "moment_body": "moment",
               "force": "force"}


def fail(message):
    print(f"read_back: {message}", file=sys.stderr)
    sys.exit(1)


def close(name, got, want):
    got, want = np.asarray(got, float), np.asarray(want, float)
    if got.shape != want.shape:
        fail(f"{name}: shape {got.shape}, stored {want.shape}")
    scale = max(1.0, float(np.max(np.abs(want))) if want.size else 1.0)
    err = float(np.max(np.abs(got - want))) if want.size else 0.0
    if err > 1e-14 * scale:
        fail(f"{name}: differs from the HDF5 file by {err:.3e}")


def arrays(data):
    pd = data.GetPointData()
    return {pd.GetArrayName(i): vtk_to_numpy(pd.GetArray(i)) for i in range(pd.GetNumberOfArrays())}


def check_polyline(name, data):
    """One cell through every point in order."""
    n = data.GetNumberOfPoints()
    if data.GetNumberOfCells() != 1:
        fail(f"{name}: {data.GetNumberOfCells()} cells, not one polyline")
    ids = data.GetCell(0).GetPointIds()
    order = [ids.GetId(i) for i in range(ids.GetNumberOfIds())]
    if order != list(range(n)):
        fail(f"{name}: the polyline does not run through the points in order")


def check_arc_length(name, s, length):
    if abs(s[0]) > 0 or abs(s[-1] - length) > 1e-12 * length or np.any(np.diff(s) <= 0):
        fail(f"{name}: s runs from {s[0]} to {s[-1]}, not increasing over [0, {length}]")


def check_equilibrium(name, data, h5, length):
    sol = h5["solution"]
    check_polyline(name, data)
    close(f"{name} points", vtk_to_numpy(data.GetPoints().GetData()), sol["position"][...])
    got = arrays(data)
    for exported, stored in EQUILIBRIUM.items():
        if exported not in got:
            fail(f"{name}: no point array {exported}")
        close(f"{name} {exported}", got[exported], sol[stored][...])
    d = np.stack([got["d1"], got["d2"], got["d3"]], axis=1)  # n×3×3
    drift = np.max(np.abs(np.einsum("nij,nkj->nik", d, d) - np.eye(3)))
    if drift > 1e-8:
        fail(f"{name}: directors not orthonormal (drift {drift:.2e})")
    check_arc_length(name, got["s"], length)


# A diagram point's exported arrays and the branch datasets they come from.
DIAGRAM = {"s": "shape_s", "d1": "shape_d1", "d2": "shape_d2", "d3": "shape_d3",
           "curvature_body": "shape_curvature", "moment_body": "shape_moment",
           "force": "shape_force"}


def expected_rows(h5, branch):
    """The diagram points in the exported order, and their times."""
    branches = h5["branches"]
    ids = [branch] if branch is not None else sorted(int(k) for k in branches if k.isdigit())
    rows = [(b, k) for b in ids for k in range(branches[str(b)]["parameter"].shape[0])]
    if branch is not None:
        p = branches[str(branch)]["parameter"][...]
        d = np.diff(p)
        if len(p) > 1 and (np.all(d > 0) or np.all(d < 0)):
            order = np.argsort(p)
            return [(branch, int(k)) for k in order], [float(p[k]) for k in order]
    return rows, [float(i) for i in range(len(rows))]


def check_diagram_point(name, data, h5, row, length):
    b, k = row
    check_polyline(name, data)
    shape = h5["branches"][str(b)]["shapes"][k]
    close(f"{name} points", vtk_to_numpy(data.GetPoints().GetData()), shape)
    got = arrays(data)
    if length == 0:
        # A continuation in the length: each point's own.
        length = float(h5["branches"][str(b)]["parameter"][k])
    check_arc_length(name, got["s"], length)
    close(f"{name} s_over_L", got["s_over_L"], np.linspace(0, 1, shape.shape[0]))
    # The whole rod at the shape points: every field as stored, the shape
    # points equally spaced in s, the directors orthonormal.
    branch = h5["branches"][str(b)]
    for exported, stored in DIAGRAM.items():
        if exported not in got:
            fail(f"{name}: no point array {exported}")
        close(f"{name} {exported}", got[exported], branch[stored][k])
    close(f"{name} s equally spaced", got["s"], np.linspace(0, length, shape.shape[0]))
    d = np.stack([got["d1"], got["d2"], got["d3"]], axis=1)
    drift = np.max(np.abs(np.einsum("nij,nkj->nik", d, d) - np.eye(3)))
    if drift > 1e-8:
        fail(f"{name}: directors not orthonormal (drift {drift:.2e})")


def read_vtp(path):
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(path))
    r.Update()
    if r.GetErrorCode() or r.GetOutput().GetNumberOfPoints() == 0:
        fail(f"{path}: VTK could not read it")
    return r.GetOutput()


# The designs of an arm study in the documented order (README, "ParaView").
ARM = [("optimum", "loaded_shape"), ("optimum", "unloaded_shape"),
       ("straight", "loaded_shape"), ("closest_straight", "loaded_shape"),
       ("closest_straight", "unloaded_shape"), ("least_curvature", "loaded_shape"),
       ("least_curvature", "unloaded_shape")]


def arm(out, h5):
    sets = ET.parse(out).getroot().find("Collection").findall("DataSet")
    stored = [f"{g}/{d}" for g, d in ARM if g in h5 and d in h5[g]]
    if len(sets) != len(stored):
        fail(f"{out}: {len(sets)} time steps for {len(stored)} stored designs")
    close(f"{out} timesteps", [float(s.get("timestep")) for s in sets], range(len(stored)))
    for s, path in zip(sets, stored):
        data = read_vtp(Path(out).parent / s.get("file"))
        check_polyline(path, data)
        close(f"{out} {path}", vtk_to_numpy(data.GetPoints().GetData()), h5[path][...])
    return len(sets)


def pvd(out, h5, length, branch):
    if "optimum" in h5:
        return arm(out, h5)
    sets = ET.parse(out).getroot().find("Collection").findall("DataSet")
    rows, times = expected_rows(h5, branch)
    if len(sets) != len(rows):
        fail(f"{out}: {len(sets)} time steps for {len(rows)} stored points")
    close(f"{out} timesteps", [float(s.get("timestep")) for s in sets], times)
    for s, row in zip(sets, rows):
        path = Path(out).parent / s.get("file")
        check_diagram_point(str(path), read_vtp(path), h5, row, length)
    return len(sets)


def xmf(out, h5, length, branch):
    r = vtk.vtkXdmfReader()
    r.SetFileName(str(out))
    r.UpdateInformation()
    steps = r.GetOutputInformation(0).Get(vtk.vtkStreamingDemandDrivenPipeline.TIME_STEPS())
    if "solution" in h5:
        r.Update()
        check_equilibrium(str(out), r.GetOutputDataObject(0), h5, length)
        return 1
    rows, times = expected_rows(h5, branch)
    if steps is None or len(steps) != len(rows):
        fail(f"{out}: {0 if steps is None else len(steps)} time steps for {len(rows)} stored points")
    close(f"{out} times", list(steps), times)
    for t, row in zip(steps, rows):
        r.UpdateTimeStep(t)
        check_diagram_point(f"{out} at {t}", r.GetOutputDataObject(0), h5, row, length)
    return len(rows)


def main():
    kind, out, h5path, length = sys.argv[1:5]
    branch = int(sys.argv[5]) if len(sys.argv) > 5 else None
    with h5py.File(h5path, "r") as h5:
        if kind == "vtp":
            check_equilibrium(out, read_vtp(out), h5, float(length))
            n = 1
        elif kind == "pvd":
            n = pvd(out, h5, float(length), branch)
        else:
            n = xmf(out, h5, float(length), branch)
    print(f"read_back: {out}: {n} time steps agree with {h5path}")


main()
