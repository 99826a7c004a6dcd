"""The example of docs/python.md, run as written on a small mesh instead of the armadillo."""

import re

import numpy as np

from conftest import SOURCE_DIR


def test_the_depth_image_example_runs(tmp_path, monkeypatch):
    text = (SOURCE_DIR / "docs/python.md").read_text()
    code = re.search(r"## Example.*?```python\n(.*?)```", text, re.S).group(1)
    assert len(code.strip().splitlines()) <= 10
    mesh = SOURCE_DIR / "tests/data/meshes/box.off"
    code = code.replace("data/meshes/armadillo.off", str(mesh))
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(code, "docs/python.md", "exec"), namespace)
    depth = namespace["depth"]
    assert depth.shape == (512, 512)
    assert np.isfinite(depth).any() and np.isinf(depth).any()
    assert (tmp_path / "depth.png").stat().st_size > 0
