#pragma once
// The Python archive object: a reader for what the archive holds and, made on the first frame
// (it opens the OpenCL device), the Explorer that renders frames. Shared by archive_binding.cpp
// (reading) and frame_binding.cpp (rendering).
#include <memory>
#include <string>

#include "insitu/archive/archive_reader.hpp"
#include "insitu/explore/explorer.hpp"

namespace insitu::python {

struct Archive {
    std::string path;
    bool damaged = false;  ///< opened with ArchiveReader::open_damaged
    std::shared_ptr<ArchiveReader> reader;
    std::unique_ptr<Explorer> explorer;

    Explorer& explore() {
        if (!explorer) explorer = std::make_unique<Explorer>(path);
        return *explorer;
    }
};

}  // namespace insitu::python
