"""examples/python_quickstart.py runs as a script and draws its figures."""

import os
import runpy

from conftest import REPO

EXAMPLE = REPO / "examples" / "python_quickstart.py"


def test_the_quickstart_notebook_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    runpy.run_path(str(EXAMPLE), run_name="__main__")
    for name in ("cantilever_shapes.png", "euler_column_diagram.png"):
        png = tmp_path / name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
        assert os.path.getsize(png) > 10_000, name
    assert (tmp_path / "euler_column.h5").is_file()
