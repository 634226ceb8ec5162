"""Shared paths: the repository's problem files and docs."""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
PROBLEMS = REPO / "problems"


@pytest.fixture
def problem_path():
    """The path of a shipped problem file by its stem."""
    return lambda name: PROBLEMS / f"{name}.toml"


def schema_paths(title):
    """The dataset paths docs/hdf5-schema.md lists under a section title."""
    lines = (REPO / "docs" / "hdf5-schema.md").read_text().splitlines()
    start = lines.index(f"### {title}")
    paths = []
    for line in lines[start + 1 :]:
        if line.startswith("#"):
            break
        if line.startswith("| `/"):
            paths.append(line.split("`")[1])
    assert paths, f"no paths under {title!r}"
    return paths
