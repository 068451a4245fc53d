"""Archive.export_cinema: a Cinema Spec D database whose data.csv names every frame written, one
row per combination, and whose PNGs are render(...).srgb8() of that row's parameters."""
import csv

import matplotlib.image
import numpy as np
import pytest

import insitu

EDITED_TF = {"points": [[0.0, 0.0, 0.3, 1.0, 0.0], [0.3, 1.0, 0.8, 0.0, 0.9]], "unit_length": 1.0}


def png_bytes(path):
    """An 8-bit PNG as its stored bytes (matplotlib returns them divided by 255)."""
    return np.rint(matplotlib.image.imread(path) * 255.0).astype(np.uint8)


def test_the_database_lists_every_frame_and_each_png_is_the_rendered_frame(archive_path,
                                                                            tmp_path):
    archive = insitu.open(archive_path)
    out = tmp_path / "frames.cdb"
    tfs = [archive.transfer_function(archive.steps[0]), EDITED_TF]
    count = archive.export_cinema(out, steps=archive.steps, tfs=tfs, azimuths=[10.0, 130.0],
                                  elevations=[-20.0])
    assert count == len(archive.steps) * 2 * 2
    with open(out / "data.csv", newline="") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["step", "view", "tf", "azimuth", "elevation", "FILE"]
    rows = rows[1:]
    assert len(rows) == count
    assert sorted(p.name for p in out.glob("*.png")) == sorted(row[5] for row in rows)
    assert {(int(r[0]), int(r[2]), float(r[3])) for r in rows} == \
        {(s, t, a) for s in archive.steps for t in (0, 1) for a in (10.0, 130.0)}
    for step, view, tf, azimuth, elevation, name in rows:
        frame = archive.render(int(step), view=int(view), tf=tfs[int(tf)],
                               azimuth=float(azimuth), elevation=float(elevation))
        assert np.array_equal(png_bytes(out / name), frame.srgb8()), name
    # The two functions give different pictures: the tf column is not decoration.
    first = [r for r in rows if r[0] == rows[0][0] and r[3] == rows[0][3]]
    assert not np.array_equal(png_bytes(out / first[0][5]), png_bytes(out / first[1][5]))


def test_defaults_are_the_stored_views_camera_and_function(archive_path, tmp_path):
    archive = insitu.open(archive_path)
    step = archive.steps[-1]
    assert archive.export_cinema(tmp_path / "stored.cdb", steps=[step]) == 1
    with open(tmp_path / "stored.cdb" / "data.csv", newline="") as f:
        rows = list(csv.reader(f))
    assert rows[1][:5] == [str(step), "0", "-1", "", ""]
    assert np.array_equal(png_bytes(tmp_path / "stored.cdb" / rows[1][5]),
                          archive.render(step).srgb8())


def test_a_step_the_archive_lacks_is_an_error_naming_it(archive_path, tmp_path):
    with pytest.raises(insitu.Error, match="12345"):
        insitu.open(archive_path).export_cinema(tmp_path / "bad.cdb", steps=[12345])
