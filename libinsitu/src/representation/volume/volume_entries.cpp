#include "representation/volume/volume_entries.hpp"

#include "archive/archive_format.hpp"
#include "archive/manifest_keys.hpp"
#include "insitu/error.hpp"
#include "representation/volume/zfp_volume.hpp"

namespace insitu::archive_format {

namespace fs = std::filesystem;

VolumeRecord::Block::Placed place_volume_block(const fs::path& archive, const VolumeBlockName& name,
                                               const float* values, const Index3& dims,
                                               const ZfpParameters& parameters) {
    const EncodedVolumeBlock encoded = encode_volume_block(values, dims, parameters);
    VolumeRecord::Block::Placed placed;
    placed.nonfinite = encoded.nonfinite;
    placed.files.push_back(place_file(
        archive, volume_relative_path(name.step, name.field, name.block, name.blocks, ".zfp"),
        encoded.stream));
    if (encoded.nonfinite > 0) {
        placed.files.push_back(place_file(
            archive, volume_relative_path(name.step, name.field, name.block, name.blocks, ".mask"),
            encoded.mask));
    }
    return placed;
}

namespace {

constexpr const char* kZfpCodec = "zfp";

nlohmann::json triple(const Index3& values) {
    return nlohmann::json::array({values[0], values[1], values[2]});
}
nlohmann::json triple(const glm::dvec3& values) {
    return nlohmann::json::array({values.x, values.y, values.z});
}
Index3 index_triple(const nlohmann::json& values) {
    return {values[0].get<std::int64_t>(), values[1].get<std::int64_t>(),
            values[2].get<std::int64_t>()};
}
glm::dvec3 vector_triple(const nlohmann::json& values) {
    return {values[0].get<double>(), values[1].get<double>(), values[2].get<double>()};
}

/// Three values of `expect` under `key`; ParseError naming the key otherwise.
const nlohmann::json& require_triple(const nlohmann::json& object, const char* key, Expect expect,
                                     const std::string& file, const std::string& where) {
    const auto& values = require(object, key, Expect::array, file, where);
    if (values.size() != 3 ||
        !std::all_of(values.begin(), values.end(),
                     [&](const nlohmann::json& value) { return holds(value, expect); })) {
        fail<ParseError>("\"", file, "\": ", where, ".", key, " ", value_text(values),
                         " is not three values of its kind");
    }
    return values;
}

/// A grid of at least one sample per axis that decoding may allocate (zfp_volume.hpp).
Index3 require_dims(const nlohmann::json& object, const std::string& file,
                    const std::string& where) {
    const Index3 dims = index_triple(require_triple(object, "dims", Expect::count, file, where));
    const bool fits = dims[0] >= 1 && dims[1] >= 1 && dims[2] >= 1 &&
                      dims[0] <= kMaxVolumeBlockSamples && dims[1] <= kMaxVolumeBlockSamples &&
                      dims[2] <= kMaxVolumeBlockSamples / dims[0] / dims[1];
    if (!fits) {
        fail<ParseError>("\"", file, "\": ", where, ".dims ", triple(dims).dump(),
                         " is not a grid a compressed field can have");
    }
    return dims;
}

/// One file of a block: relative path, bytes and CRC-32.
void check_file_keys(const nlohmann::json& object, const std::string& file,
                     const std::string& where) {
    check_relative_path(require(object, "file", Expect::string, file, where), file, where, "file");
    require(object, "bytes", Expect::count, file, where);
    require(object, "crc32", Expect::crc32, file, where);
}

void check_block(const nlohmann::json& block, const Index3& grid, const std::string& file,
                 const std::string& where) {
    const Index3 offset = index_triple(require_triple(block, "offset", Expect::count, file, where));
    const Index3 dims = require_dims(block, file, where);
    for (int axis = 0; axis < 3; ++axis) {
        if (offset[axis] > grid[axis] - dims[axis]) {
            fail<ParseError>("\"", file, "\": ", where, ": a block at ", triple(offset).dump(),
                             " of ", triple(dims).dump(), " samples leaves the grid");
        }
    }
    check_file_keys(block, file, where);
    const auto& nonfinite = require(block, "nonfinite", Expect::count, file, where);
    if (nonfinite.get<std::uint64_t>() > 0) {
        check_file_keys(require(block, "mask", Expect::object, file, where), file, where + ".mask");
    }
}

void check_volume_entry(const nlohmann::json& entry, const std::string& file,
                        const std::string& where) {
    if (require(entry, "codec", Expect::string, file, where) != kZfpCodec) {
        fail<ParseError>("\"", file, "\": ", where, ".codec ", entry["codec"].dump(),
                         " is not a codec this reader knows (\"zfp\")");
    }
    const auto& mode = require(entry, "mode", Expect::string, file, where);
    if (mode != to_string(VolumeMode::accuracy) && mode != to_string(VolumeMode::rate)) {
        fail<ParseError>("\"", file, "\": ", where, ".mode ", mode.dump(),
                         " is neither \"accuracy\" nor \"rate\"");
    }
    for (const char* key : {"tolerance", "rate", "min", "max"}) {
        require(entry, key, Expect::number, file, where);
    }
    require(entry, "nonfinite", Expect::count, file, where);
    const Index3 grid = require_dims(entry, file, where);
    require_triple(entry, "origin", Expect::number, file, where);
    const auto& spacing = require_triple(entry, "spacing", Expect::number, file, where);
    if (!std::all_of(spacing.begin(), spacing.end(),
                     [](const nlohmann::json& value) { return value.get<double>() > 0.0; })) {
        fail<ParseError>("\"", file, "\": ", where, ".spacing ", spacing.dump(),
                         " is not positive");
    }
    const auto& blocks = require(entry, "blocks", Expect::array, file, where);
    if (blocks.empty()) fail<ParseError>("\"", file, "\": ", where, ".blocks is empty");
    for (std::size_t b = 0; b < blocks.size(); ++b) {
        check_block(blocks[b], grid, file, where + ".blocks[" + std::to_string(b) + "]");
    }
}

nlohmann::json file_keys(const WrittenFile& written) {
    return {{"file", written.relative_path}, {"bytes", written.bytes}, {"crc32", written.crc32}};
}

/// Compresses and places the blocks of `volume` (the field at position `field_number` of the
/// configuration's "fields"; blocks a rank placed itself are indexed as they are), appended to
/// `written`; returns its entry.
nlohmann::json write_volume(const fs::path& archive, std::int64_t step, int field_number,
                            const VolumeRecord& volume, std::vector<WrittenFile>& written) {
    const ZfpParameters parameters{volume.mode, volume.tolerance, volume.rate, volume.threads};
    const int count = static_cast<int>(volume.blocks.size());
    nlohmann::json blocks = nlohmann::json::array();
    std::int64_t nonfinite = 0;
    for (int b = 0; b < count; ++b) {
        const VolumeRecord::Block& block = volume.blocks[b];
        if (!block.placed && static_cast<std::int64_t>(block.values.size()) !=
                                 block.dims[0] * block.dims[1] * block.dims[2]) {
            fail<InvalidArgument>("step ", step, ": compressed field of \"", volume.field,
                                  "\": block ", b, " holds ", block.values.size(), " values for ",
                                  triple(block.dims).dump(), " samples");
        }
        const VolumeRecord::Block::Placed placed =
            block.placed ? *block.placed
                         : place_volume_block(archive, {step, field_number, b, count},
                                              block.values.data(), block.dims, parameters);
        if (placed.files.size() != (placed.nonfinite > 0 ? 2u : 1u)) {
            fail<InvalidArgument>("step ", step, ": compressed field of \"", volume.field,
                                  "\": block ", b, " lists ", placed.files.size(), " files for ",
                                  placed.nonfinite, " non-finite samples");
        }
        written.insert(written.end(), placed.files.begin(), placed.files.end());
        nlohmann::json entry = file_keys(placed.files[0]);
        entry["offset"] = triple(block.offset);
        entry["dims"] = triple(block.dims);
        entry["nonfinite"] = placed.nonfinite;
        if (placed.nonfinite > 0) entry["mask"] = file_keys(placed.files[1]);
        nonfinite += placed.nonfinite;
        blocks.push_back(std::move(entry));
    }
    return {{"field", volume.field},
            {"codec", kZfpCodec},
            {"mode", to_string(volume.mode)},
            {"tolerance", volume.mode == VolumeMode::accuracy ? volume.tolerance : 0.0},
            {"rate", volume.mode == VolumeMode::rate ? volume.rate : 0.0},
            {"dims", triple(volume.dims)},
            {"origin", triple(volume.origin)},
            {"spacing", triple(volume.spacing)},
            {"min", volume.min},
            {"max", volume.max},
            {"nonfinite", nonfinite},
            {"blocks", std::move(blocks)}};
}

class VolumeEntries final : public EntryList {
public:
    const char* key() const override { return kVolumesKey; }
    const char* noun() const override { return "compressed field"; }
    const char* folder() const override { return kVolumeFolder; }

    std::vector<std::string> fields(const StepRecord& record) const override {
        std::vector<std::string> fields;
        for (const VolumeRecord& volume : record.volumes) fields.push_back(volume.field);
        return fields;
    }

    nlohmann::json write(const fs::path& archive, const InstrumentConfig&, const StepRecord& record,
                         const std::function<int(const std::string&)>& field_number,
                         std::vector<WrittenFile>& written) const override {
        nlohmann::json entries = nlohmann::json::array();
        for (const VolumeRecord& volume : record.volumes) {
            entries.push_back(
                write_volume(archive, record.step, field_number(volume.field), volume, written));
        }
        return entries;
    }

    void check(const nlohmann::json& entry, const std::string& file,
               const std::string& where) const override {
        check_volume_entry(entry, file, where);
    }

    std::vector<ListedFile> files(const std::string& archive,
                                  const nlohmann::json& entry) const override {
        return listed_volume_files(archive, entry);
    }
};

}  // namespace

const EntryList& volume_entry_list() {
    static const VolumeEntries list;
    return list;
}

std::vector<ListedFile> listed_volume_files(const std::string& archive,
                                            const nlohmann::json& entry) {
    std::vector<ListedFile> files;
    for (const nlohmann::json& block : entry.at("blocks")) {
        files.push_back(listed_entry_file(archive, block));
        if (block.contains("mask")) files.push_back(listed_entry_file(archive, block.at("mask")));
    }
    return files;
}

ArchivedVolume archived_volume(const std::string& archive, const nlohmann::json& step_entry,
                               const nlohmann::json& entry) {
    ArchivedVolume volume;
    volume.step = step_entry.at("step").get<std::int64_t>();
    volume.time = step_entry.at("time").get<double>();
    volume.field = entry.at("field").get<std::string>();
    volume.codec = entry.at("codec").get<std::string>();
    volume.mode =
        entry.at("mode") == to_string(VolumeMode::rate) ? VolumeMode::rate : VolumeMode::accuracy;
    volume.tolerance = entry.at("tolerance").get<double>();
    volume.rate = entry.at("rate").get<double>();
    volume.dims = index_triple(entry.at("dims"));
    volume.min = entry.at("min").get<double>();
    volume.max = entry.at("max").get<double>();
    volume.nonfinite = entry.at("nonfinite").get<std::int64_t>();
    volume.blocks = static_cast<int>(entry.at("blocks").size());
    for (const ListedFile& file : listed_volume_files(archive, entry)) {
        volume.bytes += file.bytes;
        volume.files.push_back(file.absolute_path);
    }
    return volume;
}

VolumeGrid read_volume(const std::string& archive, const nlohmann::json& entry) {
    VolumeGrid grid;
    grid.field = entry.at("field").get<std::string>();
    grid.dims = index_triple(entry.at("dims"));
    grid.origin = vector_triple(entry.at("origin"));
    grid.spacing = vector_triple(entry.at("spacing"));
    // Samples no block covers stay NaN: empty, as the renderers treat it.
    grid.values.assign(static_cast<std::size_t>(grid.dims[0] * grid.dims[1] * grid.dims[2]),
                       std::nanf(""));
    for (const nlohmann::json& block : entry.at("blocks")) {
        const ListedFile stream = listed_entry_file(archive, block);
        const std::vector<char> mask =
            block.contains("mask") ? read_listed_file(listed_entry_file(archive, block.at("mask")))
                                   : std::vector<char>();
        const Index3 offset = index_triple(block.at("offset"));
        const Index3 dims = index_triple(block.at("dims"));
        const std::vector<float> values =
            decode_volume_block(read_listed_file(stream), mask, dims,
                                block.at("nonfinite").get<std::int64_t>(), stream.absolute_path);
        for (std::int64_t z = 0; z < dims[2]; ++z) {
            for (std::int64_t y = 0; y < dims[1]; ++y) {
                const auto row = values.begin() + dims[0] * (y + dims[1] * z);
                std::copy(row, row + dims[0],
                          grid.values.begin() +
                              (offset[0] +
                               grid.dims[0] * (offset[1] + y + grid.dims[1] * (offset[2] + z))));
            }
        }
    }
    return grid;
}

}  // namespace insitu::archive_format
