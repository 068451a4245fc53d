// .vdb inputs (OpenVDB): one grid per file, densified over its active bounding box.
#include <sstream>

#include "capture_readers.hpp"
#include "insitu/error.hpp"
#include "insitu/openvdb_adaptor.hpp"

namespace insitu::capture::detail {

namespace {

class VdbStep : public LoadedStep {
public:
    explicit VdbStep(openvdb_adaptor::DenseGrid grid) : grid_(std::move(grid)) {}
    Field field() const override { return grid_.field(); }
    std::vector<double> default_isovalues() const override { return grid_.default_isovalues(); }
    std::string describe() const override {
        const Index3 dims = grid_.dims();
        // In double: a ratio needs no exact count, and the product cannot wrap.
        const double dense_voxels = static_cast<double>(dims[0]) * dims[1] * dims[2];
        std::ostringstream text;
        text.precision(3);
        text << "vdb " << openvdb_adaptor::to_string(grid_.grid_class()) << " \"" << grid_.name()
             << "\": " << grid_.active_voxel_count() << " active voxels, densified " << dims[0]
             << "x" << dims[1] << "x" << dims[2] << " ("
             << 100.0 * static_cast<double>(grid_.active_voxel_count()) / dense_voxels
             << "% active)";
        return text.str();
    }

private:
    openvdb_adaptor::DenseGrid grid_;
};

}  // namespace

std::unique_ptr<LoadedStep> load_vdb(const std::string& path, const InputOptions& options) {
    const openvdb::GridBase::Ptr grid = openvdb_adaptor::read_grid(path, options.array_name);
    try {
        return std::make_unique<VdbStep>(openvdb_adaptor::densify(*grid, options.field_name));
    } catch (const InvalidArgument& error) {
        fail<InvalidArgument>("\"", path, "\": ", error.what());
    }
}

}  // namespace insitu::capture::detail
