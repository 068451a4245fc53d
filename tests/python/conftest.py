"""Shared fixtures: the programs the build made and a small archive of the Gray-Scott mini-app
with proxies, a light field and a compressed field (ctest sets the paths)."""
import json
import os
import subprocess

import pytest


def tool(variable):
    """The path ctest gives in `variable`; a run without it fails (never skips)."""
    path = os.environ.get(variable)
    if not path or not os.path.exists(path):
        pytest.fail(f"{variable} is not set to a built program (run the tests through ctest)")
    return path


@pytest.fixture(scope="session")
def insitu_view():
    return tool("INSITU_VIEW")


@pytest.fixture(scope="session")
def archive_path(tmp_path_factory):
    """Gray-Scott 32^3, steps 5 and 10: a 96^2 view, 12 light-field cameras with attenuation,
    the compressed field by the feature rule."""
    folder = tmp_path_factory.mktemp("gray_scott")
    config = folder / "config.json"
    config.write_text(json.dumps({
        "fields": ["v"],
        "views": [{"azimuth": 30, "elevation": 20, "size": [96, 96]}],
        "every": 5,
        "light_field": {"cameras": 12, "size": 64, "attenuation": True},
        "volume": {}}))
    archive = folder / "gray-scott.cdb"
    subprocess.run([tool("GRAY_SCOTT"), "--size", "32", "--steps", "10", "--config", str(config),
                    "--out", str(archive)], check=True, capture_output=True)
    return str(archive)
