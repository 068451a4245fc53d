// dump_volume: writes what ArchiveReader::load_volume gives for (step, field) as raw float32,
// little-endian, x fastest, so that a tool other than libinsitu (tests/cli/volume_interop.py,
// zfpy) can be compared with the library's own reading of the archive.
//
//   dump_volume ARCHIVE STEP FIELD OUT.f32
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>

#include "insitu/archive/archive_reader.hpp"

int main(int argc, char** argv) {
    if (argc != 5) {
        std::fprintf(stderr, "usage: dump_volume ARCHIVE STEP FIELD OUT.f32\n");
        return 2;
    }
    try {
        const insitu::ArchiveReader reader(argv[1]);
        const insitu::VolumeGrid grid = reader.load_volume(std::stoll(argv[2]), argv[3]);
        std::ofstream out(argv[4], std::ios::binary);
        out.write(reinterpret_cast<const char*>(grid.values.data()),
                  static_cast<std::streamsize>(grid.values.size() * sizeof(float)));
        if (!out) {
            std::fprintf(stderr, "dump_volume: cannot write \"%s\"\n", argv[4]);
            return 1;
        }
        std::printf("%s step %s: %lld x %lld x %lld\n", argv[3], argv[2],
                    static_cast<long long>(grid.dims[0]), static_cast<long long>(grid.dims[1]),
                    static_cast<long long>(grid.dims[2]));
    } catch (const std::exception& error) {
        std::fprintf(stderr, "dump_volume: %s\n", error.what());
        return 1;
    }
    return 0;
}
