"""insitu.open: an archive's index, proxies, light fields and compressed field as numpy arrays."""
import json
import os
import shutil

import numpy as np
import pytest

import insitu


def test_index_matches_the_manifest(archive_path):
    archive = insitu.open(archive_path)
    with open(os.path.join(archive_path, "manifest.json")) as f:
        manifest = json.load(f)
    assert archive.steps == [entry["step"] for entry in manifest["steps"]] == [5, 10]
    assert archive.times == [entry["time"] for entry in manifest["steps"]]
    assert archive.fields == ["v"]
    assert archive.views == [{"view": 0, "field": "v", "azimuth": 30.0, "elevation": 20.0}]
    assert archive.manifest == manifest
    assert archive.diagnostics == []
    assert archive.damage() == []


def test_proxies_are_views_with_the_archive_channel_names(archive_path):
    proxies = insitu.open(archive_path).proxies(5)
    attenuation = proxies["attenuation"]
    intervals = len(proxies.intervals) - 1
    assert attenuation.shape == (96, 96, intervals) and attenuation.dtype == np.float32
    assert proxies.channels("attenuation") == [f"attenuation.a{j:02d}" for j in range(intervals)]
    # A view of the reader's buffer: the same memory each time, read-only, kept alive by it.
    assert np.shares_memory(attenuation, proxies["attenuation"])
    assert not attenuation.flags.writeable
    assert proxies.channels("rendering") == ["rendering.R", "rendering.G", "rendering.B",
                                             "rendering.A"]
    # Depth layers are stacked (a copy), one channel per layer.
    depth = proxies["depth"]
    assert depth.shape[:2] == (96, 96)
    assert depth.shape[2] == len(proxies.isovalues) == len(proxies.channels("depth"))
    # sum_j a_j = 1 - T = the ground truth's alpha (both stored in half precision).
    alpha = proxies["rendering"][..., 3]
    assert np.abs(attenuation.sum(axis=2) - alpha).max() < 2e-2
    assert alpha.max() > 0.1


def test_arrays_outlive_the_objects_they_view(archive_path):
    attenuation = insitu.open(archive_path).proxies(10)["attenuation"]
    copy = np.array(attenuation)
    del attenuation
    attenuation = insitu.open(archive_path).proxies(10)["attenuation"]
    assert np.array_equal(attenuation, copy)


def test_a_missing_proxy_names_what_the_view_holds(archive_path):
    proxies = insitu.open(archive_path).proxies(5)
    assert "distortion" not in proxies
    with pytest.raises(insitu.InvalidArgument, match="holds depth, attenuation"):
        proxies["distortion"]


def test_compressed_field_within_its_tolerance_of_the_range(archive_path):
    archive = insitu.open(archive_path)
    [entry] = archive.volumes(10)
    volume = archive.volume(10)
    assert volume.shape == entry["dims"] == (32, 32, 32)
    assert volume.flags.f_contiguous  # indexed [x, y, z] over the decoder's x-fastest buffer
    assert entry["min"] - entry["tolerance"] <= np.nanmin(volume)
    assert np.nanmax(volume) <= entry["max"] + entry["tolerance"]
    assert np.nanmax(volume) - np.nanmin(volume) > 0.5 * (entry["max"] - entry["min"])


def test_light_field_cameras_read_as_asked(archive_path):
    archive = insitu.open(archive_path)
    [entry] = archive.light_fields(5)
    assert entry["field"] == "v" and entry["cameras"] == 12
    light_field = archive.light_field(5, "v", [2, 7])
    assert light_field.cameras == [2, 7]
    images = light_field.camera(7)
    assert images["segment0"].shape == (64, 64, 4)
    assert images["depth"].shape == (64, 64)
    assert images["attenuation"].shape == (64, 64, len(light_field.intervals) - 1)
    with pytest.raises(insitu.InvalidArgument, match="camera 3 is not held"):
        light_field.camera(3)


def test_damage_is_listed_and_reading_it_raises_io_error(archive_path, tmp_path):
    damaged = tmp_path / "damaged.cdb"
    shutil.copytree(archive_path, damaged)
    exr = damaged / "proxies" / "step000010_view0.exr"
    exr.write_bytes(exr.read_bytes()[:1000])
    archive = insitu.open(str(damaged), damaged=True)
    problems = archive.damage()
    assert len(problems) == 1 and "step000010_view0.exr" in problems[0]
    with pytest.raises(insitu.IoError, match="step000010_view0.exr") as raised:
        archive.proxies(10)
    assert isinstance(raised.value, OSError) and isinstance(raised.value, insitu.Error)
    assert "\n" not in str(raised.value)


def test_errors_have_the_library_types_and_messages(archive_path, tmp_path):
    with pytest.raises(insitu.IoError, match="is not a directory"):
        insitu.open(str(tmp_path / "nowhere"))
    broken = tmp_path / "broken.cdb"
    broken.mkdir()
    (broken / "manifest.json").write_text("{not json")
    with pytest.raises(insitu.Error, match="manifest.json"):
        insitu.open(str(broken))
    with pytest.raises(insitu.InvalidArgument, match="7") as raised:
        insitu.open(archive_path).proxies(7)
    assert isinstance(raised.value, ValueError)
