"""examples/python/explore_and_simulate.py, run as a script."""
import os
import subprocess
import sys

import matplotlib.image

import insitu


def test_example_runs_and_draws_its_figure(tmp_path):
    script = os.path.join(os.environ["INSITU_SOURCE_DIR"], "examples", "python",
                          "explore_and_simulate.py")
    result = subprocess.run([sys.executable, script, str(tmp_path)], capture_output=True,
                            text=True)
    assert result.returncode == 0, result.stderr
    assert insitu.open(str(tmp_path / "heat.cdb")).steps == [10, 20, 30, 40]
    figure = matplotlib.image.imread(str(tmp_path / "explore.png"))
    assert figure.shape[0] > 400 and figure[..., :3].std() > 0.05
