"""ParaView opens a file of `cosserat export` and counts its time steps.
Run by pvpython or pvbatch from tests/export.rs:

    paraview_steps.py FILE STEPS

Prints `paraview: ok` when ParaView reads points and STEPS time steps.
"""
import sys

from paraview.simple import OpenDataFile

path, steps = sys.argv[1], int(sys.argv[2])
reader = OpenDataFile(path)
if reader is None:
    sys.exit(f"paraview: no reader for {path}")
times = list(reader.TimestepValues or [])
if isinstance(reader.TimestepValues, float):
    times = [reader.TimestepValues]
reader.UpdatePipeline(times[-1] if times else 0.0)
points = reader.GetDataInformation().GetNumberOfPoints()
print(f"paraview: {type(reader).__name__} {path}: {len(times)} time steps, {points} points")
if len(times) != steps or points == 0:
    sys.exit(f"paraview: expected {steps} time steps and some points")
print("paraview: ok")
