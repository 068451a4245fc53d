"""The compressed field read without libinsitu (issue 40): zfpy (Debian python3-zfpy) decodes an
archive's block files as the manifest lists them, and the result must equal what
ArchiveReader::load_volume gives (dump_volume's file) and the original field within the tolerance.

  volume_interop.py make INPUT.f32             writes the test field (raw float32, x fastest)
  volume_interop.py check ARCHIVE STEP DUMP.f32 INPUT.f32

Exit 0 when every check holds, 1 with a line naming the check otherwise. A missing zfpy is a
failure, not a skip: scripts/setup installs python3-zfpy.
"""
import json
import os
import sys
import zlib

import numpy as np

# x fastest on disk: numpy's (z, y, x) C order. Odd sizes (not multiples of ZFP's 4^3 blocks).
DIMS = (37, 30, 23)
# Samples made non-finite, which ZFP cannot carry: the archive's mask must bring them back.
NONFINITE = [(3, 4, 5, np.nan), (36, 29, 22, np.inf), (10, 0, 7, np.nan)]


def fail(message):
    print("volume_interop: " + message, file=sys.stderr)
    sys.exit(1)


def make(path):
    x, y, z = np.meshgrid(*(np.linspace(0.0, 1.0, n) for n in DIMS), indexing="ij")
    field = (np.sin(6.0 * x) * np.cos(5.0 * y) + 0.5 * np.sin(9.0 * z * x) + 0.1 * z).astype(
        np.float32)
    for i, j, k, value in NONFINITE:
        field[i, j, k] = value
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    field.transpose(2, 1, 0).astype("<f4").tofile(path)


def read_checked(archive, entry):
    """The bytes of a file the manifest names, with its size and CRC-32 checked."""
    with open(os.path.join(archive, entry["file"]), "rb") as f:
        data = f.read()
    if len(data) != entry["bytes"] or zlib.crc32(data) != entry["crc32"]:
        fail("%s: %d bytes, CRC-32 %d; the manifest says %d, %d" %
             (entry["file"], len(data), zlib.crc32(data), entry["bytes"], entry["crc32"]))
    return data


def decode_block(archive, block):
    import zfpy  # noqa: E402 (imported here so that `make` needs numpy only)

    values = zfpy.decompress_numpy(read_checked(archive, block))
    shape = tuple(reversed(block["dims"]))
    if values.dtype != np.float32 or values.shape != shape:
        fail("%s: zfpy gives %s %s, the manifest declares float32 %s" %
             (block["file"], values.dtype, values.shape, shape))
    values = np.array(values)
    if "mask" in block:  # zlib-deflated bits, x fastest, LSB first
        bits = np.unpackbits(np.frombuffer(zlib.decompress(read_checked(archive, block["mask"])),
                                           np.uint8), bitorder="little")[:values.size]
        values.reshape(-1)[bits.astype(bool)] = np.nan
    return values


def assemble(archive, volume):
    dims = volume["dims"]
    grid = np.full(tuple(reversed(dims)), np.nan, np.float32)
    for block in volume["blocks"]:
        (i, j, k), (nx, ny, nz) = block["offset"], block["dims"]
        grid[k:k + nz, j:j + ny, i:i + nx] = decode_block(archive, block)
    return grid


def check(archive, step, dump_path, input_path):
    try:
        import zfpy  # noqa: F401
    except ImportError:
        fail("python3-zfpy is not installed for %s (scripts/setup installs it)" % sys.executable)
    with open(os.path.join(archive, "manifest.json")) as f:
        manifest = json.load(f)
    entries = [s for s in manifest["steps"] if s["step"] == step and s.get("volumes")]
    if not entries:
        fail("step %d of %s lists no volume" % (step, archive))
    volume = entries[0]["volumes"][0]
    if volume["codec"] != "zfp" or volume["mode"] != "accuracy":
        fail("expected a ZFP fixed-accuracy volume, got %s %s" % (volume["codec"], volume["mode"]))
    shape = tuple(reversed(DIMS))
    if tuple(reversed(volume["dims"])) != shape:
        fail("the manifest declares dims %s, the input has %s" % (volume["dims"], list(DIMS)))
    by_zfpy = assemble(archive, volume)
    by_libinsitu = np.fromfile(dump_path, "<f4").reshape(shape)
    if not np.array_equal(by_zfpy, by_libinsitu, equal_nan=True):
        differ = np.count_nonzero(~((by_zfpy == by_libinsitu) |
                                    (np.isnan(by_zfpy) & np.isnan(by_libinsitu))))
        fail("zfpy and load_volume differ in %d samples" % differ)
    original = np.fromfile(input_path, "<f4").reshape(shape)
    finite = np.isfinite(original)
    if not np.array_equal(finite, ~np.isnan(by_zfpy)):
        fail("non-finite samples: the original has %d, zfpy's decoding %d NaN" %
             (np.count_nonzero(~finite), np.count_nonzero(np.isnan(by_zfpy))))
    if volume["nonfinite"] != np.count_nonzero(~finite):
        fail("the manifest counts %d non-finite samples, the original has %d" %
             (volume["nonfinite"], np.count_nonzero(~finite)))
    error = float(np.max(np.abs(by_zfpy[finite].astype(np.float64) - original[finite])))
    if not error <= volume["tolerance"]:
        fail("largest error %.3g exceeds the tolerance %.3g" % (error, volume["tolerance"]))
    print("zfpy read %d block(s) of step %d: equal to load_volume, %d non-finite restored, "
          "largest error %.3g <= tolerance %.3g" %
          (len(volume["blocks"]), step, volume["nonfinite"], error, volume["tolerance"]))


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "make":
        make(sys.argv[2])
    elif len(sys.argv) == 6 and sys.argv[1] == "check":
        check(sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5])
    else:
        fail("usage: volume_interop.py make INPUT.f32 | check ARCHIVE STEP DUMP.f32 INPUT.f32")
