"""insitu.Instrument: numpy arrays of every layout handed over without a copy, the same
archive as the contiguous array gives; errors as status or, when asked, typed exceptions."""
import threading
import time

import numpy as np
import pytest

import insitu

N = 24


def blob(shape=(N, N, N)):
    """A Gaussian blob indexed [x, y, z], off-centre so that every axis matters."""
    x, y, z = np.meshgrid(*[np.linspace(-1.0, 1.0, n) for n in shape], indexing="ij")
    return np.exp(-((x - 0.3) ** 2 + 2.0 * (y + 0.2) ** 2 + 0.5 * z ** 2) * 3.0)


def config(archive, **extra):
    return {"fields": ["v"], "views": [{"azimuth": 30, "elevation": 20, "size": [48, 48]}],
            "every": 1, "archive": str(archive), "volume": False, **extra}


def attenuation_of(archive):
    return np.array(insitu.open(str(archive)).proxies(0)["attenuation"])


def run_one(archive, data, **keywords):
    with insitu.Instrument(config(archive), log=False) as instrument:
        assert instrument.execute(0, 0.0, {"v": data}, **keywords) == insitu.Status.ok, \
            instrument.last_error
    return attenuation_of(archive)


def test_every_layout_gives_the_contiguous_arrays_archive(tmp_path):
    field = blob()
    reference = run_one(tmp_path / "reference.cdb", np.asfortranarray(field))
    assert reference.max() > 0.01
    padded = np.zeros((2 * N, N + 3, 3 * N))
    padded[::2, 1:N + 1, ::3] = field
    layouts = {
        "c_order": np.ascontiguousarray(field),
        "strided_view": padded[::2, 1:N + 1, ::3],
        "transposed_view": np.ascontiguousarray(field.transpose(2, 1, 0)).transpose(2, 1, 0),
        "float32": np.asfortranarray(field, dtype=np.float32),
    }
    for name, data in layouts.items():
        assert np.array_equal(run_one(tmp_path / f"{name}.cdb", data), reference), name


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.int16])
def test_integer_types_match_their_float64_values(tmp_path, dtype):
    values = np.rint(blob() * 200.0).astype(dtype)
    assert np.array_equal(run_one(tmp_path / "int.cdb", values),
                          run_one(tmp_path / "float.cdb", values.astype(np.float64)))


def test_ghost_layers_are_skipped(tmp_path):
    field = blob()
    with_ghosts = np.full((N + 2, N + 4, N + 2), 1e6)
    with_ghosts[1:-1, 2:-2, 1:-1] = field
    reference = run_one(tmp_path / "interior.cdb", field)
    assert np.array_equal(run_one(tmp_path / "keyword.cdb", with_ghosts,
                                  ghost_layers=(1, 2, 1)), reference)
    assert np.array_equal(
        run_one(tmp_path / "field.cdb", insitu.Field(with_ghosts, ghost_layers=((1, 2, 1),
                                                                                (1, 2, 1)))),
        reference)


def test_selects_follows_the_cadence_and_finalize_ends_the_run(tmp_path):
    instrument = insitu.Instrument(config(tmp_path / "a.cdb", every=3), log=False)
    assert [instrument.selects(step) for step in range(5)] == [True, False, False, True, False]
    assert instrument.execute(1, 0.1, {}) == insitu.Status.not_selected
    assert instrument.execute(3, 0.3, {"v": blob()}) == insitu.Status.ok
    assert instrument.finalize() == insitu.Status.ok
    assert instrument.statistics["steps_written"] == 1
    assert instrument.execute(6, 0.6, {"v": blob()}) == insitu.Status.error
    assert "finalize" in instrument.last_error
    assert insitu.open(str(tmp_path / "a.cdb")).steps == [3]


def test_bad_arrays_are_refused_naming_the_field(tmp_path):
    instrument = insitu.Instrument(config(tmp_path / "a.cdb"), log=False)
    with pytest.raises(insitu.InvalidArgument, match=r'field "v": dtype int32'):
        instrument.execute(0, 0.0, {"v": np.zeros((4, 4, 4), dtype=np.int32)})
    with pytest.raises(insitu.InvalidArgument, match=r"2 dimensions"):
        instrument.execute(0, 0.0, {"v": np.zeros((4, 4))})
    with pytest.raises(insitu.InvalidArgument, match=rf"axis 0 has a stride of -{N * N * 8} bytes"):
        instrument.execute(0, 0.0, {"v": blob()[::-1]})
    with pytest.raises(insitu.InvalidArgument, match=r"expected a numpy array"):
        instrument.execute(0, 0.0, {"v": [[[1.0]]]})
    instrument.finalize()


def test_run_failures_are_a_status_unless_raise_errors(tmp_path):
    quiet = insitu.Instrument(config(tmp_path / "a.cdb"), log=False)
    assert quiet.execute(0, 0.0, {"w": blob()}) == insitu.Status.error
    assert '"v"' in quiet.last_error and quiet.first_error == quiet.last_error
    quiet.finalize()
    loud = insitu.Instrument(config(tmp_path / "b.cdb"), raise_errors=True, log=False)
    with pytest.raises(insitu.InvalidArgument, match='"v"'):
        loud.execute(0, 0.0, {"w": blob()})
    loud.finalize()
    with pytest.raises(insitu.StateError):
        loud.execute(1, 1.0, {"v": blob()})


def test_a_bad_configuration_raises_naming_the_key(tmp_path):
    with pytest.raises(insitu.ParseError, match=r'"evry" \(did you mean "every"\?\)'):
        insitu.Instrument({"evry": 3, "archive": str(tmp_path / "a.cdb")})
    path = tmp_path / "config.json"
    path.write_text("{")
    with pytest.raises(insitu.ParseError):
        insitu.Instrument(path)


def test_execute_releases_the_gil(tmp_path):
    field = blob((64, 64, 64))
    instrument = insitu.Instrument(config(tmp_path / "a.cdb", views=[{"size": [256, 256]}]),
                                   log=False)
    counts = []
    stop = threading.Event()

    def count():
        n = 0
        while not stop.is_set():
            n += 1
            if n % 1000 == 0:
                counts.append(n)

    thread = threading.Thread(target=count)
    thread.start()
    time.sleep(0.05)
    before = len(counts)
    started = time.perf_counter()
    assert instrument.execute(0, 0.0, {"v": field}) == insitu.Status.ok
    seconds = time.perf_counter() - started
    during = len(counts) - before
    stop.set()
    thread.join()
    instrument.finalize()
    assert seconds > 0.02, "execute too quick to tell"
    # Held through the call, the GIL would let the counter run only at its ends (switches every
    # 5 ms): far fewer rounds than a counter running alongside the whole call.
    assert during > 10, f"{during} thousand counts in {seconds:.3f} s"


def test_a_comm_that_is_not_an_mpi4py_communicator_is_refused(tmp_path):
    with pytest.raises(insitu.InvalidArgument, match="comm.*(mpi4py|without MPI)"):
        insitu.Instrument(config(tmp_path / "comm.cdb"), comm=3)
