"""Archive.render equals insitu-view render's output bit for bit (its EXR and its PNGs)."""
import json
import subprocess

import matplotlib.image
import numpy as np
import pytest

import insitu

EDITED_TF = {"points": [[0.0, 0.0, 0.3, 1.0, 0.0], [0.3, 1.0, 0.8, 0.0, 0.9]], "unit_length": 1.0}

# (Python keywords, the same request as insitu-view render flags)
REQUESTS = [
    ({}, []),
    ({"azimuth": 75.0, "elevation": -10.5}, ["--azimuth", "75", "--elevation", "-10.5"]),
    ({"azimuth": 50, "source": "single", "tf": EDITED_TF, "opacity_scale": {3: 0.5, 4: 2.0}},
     ["--azimuth", "50", "--source", "single", "--tf", "TF", "--opacity-scale", "3=0.5,4=2"]),
    ({"source": "lightfield", "azimuth": 100, "lights": ["camera", (30, 40, 0.7)], "ao": True,
      "enhance": (0.5, 1.2)},
     ["--source", "lightfield", "--azimuth", "100", "--light", "camera", "--light", "30,40,0.7",
      "--ao", "--enhance", "0.5,1.2"]),
    ({"source": "volume", "azimuth": 200, "elevation": 35}, ["--source", "volume", "--azimuth",
                                                              "200", "--elevation", "35"]),
]


def png_bytes(path):
    """An 8-bit PNG as its stored bytes (matplotlib returns them divided by 255)."""
    return np.rint(matplotlib.image.imread(path) * 255.0).astype(np.uint8)


@pytest.mark.parametrize("keywords,flags", REQUESTS)
def test_frame_equals_insitu_view_render(archive_path, insitu_view, tmp_path, keywords, flags):
    tf_path = tmp_path / "tf.json"
    tf_path.write_text(json.dumps(EDITED_TF))
    flags = [str(tf_path) if flag == "TF" else flag for flag in flags]
    frame = insitu.open(archive_path).render(10, **keywords)
    exr, png, mask = tmp_path / "frame.exr", tmp_path / "frame.png", tmp_path / "mask.png"
    for out, extra in ((exr, []), (png, ["--mask", str(mask)])):
        subprocess.run([insitu_view, "render", archive_path, "--step", "10", *flags,
                        "--out", str(out), *extra], check=True, capture_output=True)
    expected = insitu.read_exr(str(exr))
    assert frame.rgba.shape == expected.shape
    assert np.array_equal(frame.rgba, expected, equal_nan=True)
    assert np.array_equal(frame.srgb8(), png_bytes(png))
    assert np.array_equal(insitu.to_srgb8(frame.confidence), png_bytes(mask))
    assert frame.rgba[..., 3].max() > 0.05  # something was drawn


def test_frame_reports_what_made_it(archive_path):
    archive = insitu.open(archive_path)
    stored = archive.render(5)
    assert not stored.synthesised_view and stored.colour_source == "stored"
    assert np.all(stored.confidence == 1.0)
    turned = archive.render(5, azimuth=120, source="single")
    assert turned.synthesised_view and turned.proxy_source == "single"
    assert turned.confidence.min() < 1.0
    assert archive.render(5, azimuth=120, source="volume").proxy_source == "volume"


def test_srgb8_of_known_values():
    linear = np.array([[[0.0], [1.0], [0.5], [0.002]]], dtype=np.float32)
    # sRGB(0.5) = 0.7354 -> 187.5 -> 188; 0.002 is on the linear segment: 12.92 * 0.002 * 255.
    assert insitu.to_srgb8(linear).ravel().tolist() == [0, 255, 188, 7]
    rgba = np.array([[[0.25, 0.0, 0.0, 0.5]]], dtype=np.float32)  # premultiplied
    assert insitu.to_srgb8(rgba).ravel().tolist() == [188, 0, 0, 128]


def test_bad_requests_name_the_value(archive_path):
    archive = insitu.open(archive_path)
    with pytest.raises(insitu.InvalidArgument, match=r"elevation = 91"):
        archive.render(5, elevation=91)
    with pytest.raises(insitu.InvalidArgument, match="source"):
        archive.render(5, source="teapot")
    with pytest.raises(insitu.InvalidArgument, match="scale -1 is negative"):
        archive.render(5, opacity_scale={2: -1})
    with pytest.raises(insitu.ParseError):
        archive.render(5, tf={"points": "none"})
    with pytest.raises(insitu.InvalidArgument, match="step 6"):
        archive.render(6)
