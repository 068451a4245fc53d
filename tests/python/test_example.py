"""examples/python/explore_and_simulate.py, run as a script, and its notebook, run cell by cell."""
import base64
import io
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


def test_notebook_runs_every_cell_and_draws_its_figures(tmp_path):
    """examples/python/explore_and_simulate.ipynb executed cell by cell (Debian's nbclient and
    ipykernel, installed by scripts/setup), in a kernel of this interpreter."""
    import json

    import nbclient
    import nbformat
    notebook_path = os.path.join(os.environ["INSITU_SOURCE_DIR"], "examples", "python",
                                 "explore_and_simulate.ipynb")
    notebook = nbformat.read(notebook_path, as_version=4)
    # A kernel spec of this very interpreter: "python3" on PATH may be another one, without
    # numpy or the module.
    spec = tmp_path / "jupyter" / "kernels" / "insitu-test"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "insitu test", "language": "python"}))
    environment = {"JUPYTER_PATH": str(tmp_path / "jupyter"),
                   "INSITU_EXAMPLE_OUT": str(tmp_path / "out"),
                   "MPLBACKEND": "module://matplotlib_inline.backend_inline",
                   # The module this test imported, wherever the kernel's working directory is.
                   "PYTHONPATH": os.path.dirname(os.path.abspath(insitu.__file__)),
                   "PYDEVD_DISABLE_FILE_VALIDATION": "1"}
    saved = {key: os.environ.get(key) for key in environment}
    os.environ.update(environment)
    try:
        nbclient.NotebookClient(notebook, kernel_name="insitu-test", timeout=600,
                                resources={"metadata": {"path": str(tmp_path)}}).execute()
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
    outputs = [output for cell in notebook.cells if cell.cell_type == "code"
               for output in cell.get("outputs", [])]
    assert not [output for output in outputs if output.output_type == "error"]
    figures = [output for output in outputs if "image/png" in output.get("data", {})]
    assert len(figures) == 3  # the strip, the orbit, the edit
    archive = insitu.open(str(tmp_path / "out" / "heat-notebook.cdb"))
    assert archive.steps == [10, 20, 30, 40]
    for figure in figures:  # each a real picture, not a blank canvas
        png = base64.b64decode(figure["data"]["image/png"])
        pixels = matplotlib.image.imread(io.BytesIO(png), format="png")
        assert pixels.shape[1] > 600 and pixels[..., :3].std() > 0.05
