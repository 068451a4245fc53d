// libFuzzer harness: the compressed field's block decoder
// (src/representation/volume/zfp_volume.hpp) on any bytes. The first byte picks the grid the
// manifest would declare (so the header check passes for inputs that keep a valid header and fails
// for the rest); the others are the ZFP stream. An IoError is the documented outcome for a stream
// that is not one; anything else escaping, or any sanitizer report (a read past the buffer above
// all), is a finding.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "insitu/error.hpp"
#include "representation/volume/zfp_volume.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    // The seed's grid first; odd and tiny grids, and one of a single sample.
    static const insitu::Index3 kGrids[] = {{8, 6, 5}, {4, 4, 4}, {1, 1, 1}, {13, 2, 7}};
    const insitu::Index3 dims = kGrids[data[0] % 4];
    const std::vector<char> stream(data + 1, data + size);
    try {
        const std::vector<float> values =
            insitu::archive_format::decode_volume_block(stream, {}, dims, 0, "fuzz.zfp");
        if (values.size() != static_cast<std::size_t>(dims[0] * dims[1] * dims[2]))
            __builtin_trap();
    } catch (const insitu::IoError&) {
    }
    return 0;
}
