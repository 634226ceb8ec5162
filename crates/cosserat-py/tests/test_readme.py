"""The README's Python snippet runs and says what its comments say."""

import math

from conftest import REPO

# Mattiasson (1981), Table 1, k = 1 (as in test_solve.py).
MATTIASSON_TIP = (0.30172, 0.0, 1.0 - 0.05643)


def readme_snippet():
    text = (REPO / "README.md").read_text()
    section = text[text.index("## Python\n") :]
    start = section.index("```python\n") + len("```python\n")
    return section[start : section.index("```", start)]


def test_the_readme_snippet(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "problems").symlink_to(REPO / "problems")
    scope = {}
    exec(compile(readme_snippet(), "README.md", "exec"), scope)
    for got, published in zip(scope["eq"].tip, MATTIASSON_TIP):
        assert abs(got - published) <= 1e-5
    assert scope["eq"].verdict == "stable"
    euler = math.pi**2 / 4
    assert abs(scope["d"].special_points[0].parameter - euler) <= 1e-8 * euler
    assert (tmp_path / "column.h5").is_file()
