#include "insitu/capture_input.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>

#include "capture_readers.hpp"
#include "insitu/error.hpp"

namespace insitu::capture {

std::string to_string(InputKind kind) {
    switch (kind) {
        case InputKind::raw:
            return "raw";
        case InputKind::vti:
            return "vti";
        case InputKind::pvd:
            return "pvd";
        case InputKind::vdb:
            return "vdb";
    }
    return "unknown";
}

InputKind input_kind(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".vti") return InputKind::vti;
    if (ext == ".pvd") return InputKind::pvd;
    if (ext == ".vdb") return InputKind::vdb;
    return InputKind::raw;
}

bool supported(InputKind kind) {
    switch (kind) {
        case InputKind::raw:
            return true;
        case InputKind::vti:
        case InputKind::pvd:
#ifdef INSITU_CAPTURE_WITH_VTK
            return true;
#else
            return false;
#endif
        case InputKind::vdb:
#ifdef INSITU_CAPTURE_WITH_OPENVDB
            return true;
#else
            return false;
#endif
    }
    return false;
}

namespace {

[[noreturn]] void fail_unsupported(const std::string& path, InputKind kind) {
    fail<InvalidArgument>("\"", path, "\": ", to_string(kind), " input needs ",
                          kind == InputKind::vdb ? "OpenVDB" : "VTK",
                          ", and this insitu-capture was built without it");
}

class RawStep : public LoadedStep {
public:
    RawStep(RawVolume volume, std::string field_name)
        : volume_(std::move(volume)), field_name_(std::move(field_name)) {}
    Field field() const override { return volume_.field(field_name_); }
    std::string describe() const override {
        const RawOptions& o = volume_.options();
        std::ostringstream text;
        text << "raw " << to_string(o.type) << (o.big_endian ? " big-endian " : " ") << o.dims[0]
             << "x" << o.dims[1] << "x" << o.dims[2]
             << (volume_.converted() ? " (converted to float32)" : "");
        return text.str();
    }

private:
    RawVolume volume_;
    std::string field_name_;
};

}  // namespace

std::vector<InputStep> expand_pvd(const std::string& pvd_path) {
#ifdef INSITU_CAPTURE_WITH_VTK
    return detail::read_pvd(pvd_path);
#else
    fail_unsupported(pvd_path, InputKind::pvd);
#endif
}

std::unique_ptr<LoadedStep> load_step(const InputStep& step, const InputOptions& options) {
    if (!supported(step.kind)) fail_unsupported(step.path, step.kind);
    switch (step.kind) {
        case InputKind::raw:
            if (!options.raw) {
                fail<InvalidArgument>("\"", step.path,
                                      "\": not .vti, .pvd or .vdb, so read as raw, which needs "
                                      "--raw-dims and --raw-type");
            }
            return std::make_unique<RawStep>(read_raw(step.path, *options.raw), options.field_name);
        case InputKind::pvd:
            fail<InvalidArgument>("\"", step.path, "\": expand a .pvd collection with expand_pvd");
#ifdef INSITU_CAPTURE_WITH_VTK
        case InputKind::vti:
            return detail::load_vti(step.path, options);
#endif
#ifdef INSITU_CAPTURE_WITH_OPENVDB
        case InputKind::vdb:
            return detail::load_vdb(step.path, options);
#endif
        default:
            fail_unsupported(step.path, step.kind);
    }
}

}  // namespace insitu::capture
