// The header guard of every libinsitu EXR (check_headers, exr_frame.hpp): walks the headers of a
// file already in memory and refuses what a libinsitu archive never holds before OpenEXR
// allocates what a header declares (issue 19). IoError naming the file and the part.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfVersion.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <map>

#include "archive/exr_frame.hpp"

namespace insitu::archive_format {

namespace {

/// Checks that OpenEXR will read exactly `size` bytes for this attribute, so its parse stays in
/// step with skip_header's walk: a channel list is read entry by entry up to its terminating
/// null, not by its declared size (a fuzzed list shorter than its entries made OpenEXR read the
/// next bytes as attributes, one of them a 1.8 GB string). Types libinsitu never writes are
/// refused, since each has a reader of its own with sizes inside its value.
void check_attribute_value(const std::vector<char>& bytes, std::size_t at, std::size_t name_end,
                           std::size_t type_end, std::size_t value, std::size_t size,
                           const PartContext& where) {
    const std::string name(&bytes[at], name_end - at);
    const std::string type(&bytes[name_end + 1], type_end - name_end - 1);
    static const std::map<std::string, std::size_t> fixed_sizes = {
        {"int", 4}, {"float", 4},       {"double", 8},   {"box2i", 16},
        {"v2f", 8}, {"compression", 1}, {"lineOrder", 1}};
    const auto fixed = fixed_sizes.find(type);
    if (fixed != fixed_sizes.end()) {
        if (size != fixed->second) {
            where.error("attribute \"" + name + "\" of type " + type + " declares " +
                        std::to_string(size) + " bytes (it has " + std::to_string(fixed->second) +
                        ")");
        }
        return;
    }
    if (type == "string") return;  // read as exactly `size` bytes
    if (type != "chlist") {
        where.error("attribute \"" + name + "\" has type \"" + type +
                    "\", which libinsitu archives do not hold");
    }
    // Entries: name\0, then pixel type (int32), pLinear + 3 reserved bytes, x and y sampling
    // (int32 each); a null byte ends the list.
    const std::size_t end = value + size;
    std::size_t entry = value;
    for (;;) {
        const auto terminator = std::find(bytes.begin() + static_cast<std::ptrdiff_t>(entry),
                                          bytes.begin() + static_cast<std::ptrdiff_t>(end), '\0');
        const auto stop = static_cast<std::size_t>(terminator - bytes.begin());
        if (stop == end) break;
        if (stop == entry) {
            if (entry + 1 == end) return;  // the list's null byte is its last byte
            break;
        }
        entry = stop + 1 + 16;
        if (entry > end) break;
    }
    where.error("attribute \"" + name + "\": channel list does not fill its " +
                std::to_string(size) + " bytes exactly");
}

/// Walks the attribute list of one header from `at` without allocating anything: each attribute
/// is name\0 type\0 int32 size value[size], and a size past the end of the file is refused here
/// (OpenEXR would allocate it first). Returns where the header ends; an empty header (the
/// multi-part terminator) ends right after its null byte.
std::size_t skip_header(const std::vector<char>& bytes, std::size_t at, const PartContext& where) {
    const auto name_end = [&](std::size_t from) {
        // OpenEXR names are at most 255 bytes (31 in older files).
        const std::size_t limit = std::min(bytes.size(), from + 256);
        const auto end = std::find(bytes.begin() + static_cast<std::ptrdiff_t>(from),
                                   bytes.begin() + static_cast<std::ptrdiff_t>(limit), '\0');
        if (end == bytes.begin() + static_cast<std::ptrdiff_t>(limit)) {
            where.error("attribute name or type at byte " + std::to_string(from) +
                        " is unterminated");
        }
        return static_cast<std::size_t>(end - bytes.begin());
    };
    for (;;) {
        if (at >= bytes.size()) where.error("header runs past the end of the file");
        const std::size_t name = name_end(at);
        if (name == at) return at + 1;  // the empty name that ends the header
        const std::size_t type = name_end(name + 1);
        if (bytes.size() - (type + 1) < 4) where.error("header runs past the end of the file");
        std::int32_t size = 0;
        for (int b = 3; b >= 0; --b) {  // little-endian, as every EXR integer
            size = static_cast<std::int32_t>(static_cast<std::uint32_t>(size) << 8 |
                                             static_cast<unsigned char>(bytes[type + 1 + b]));
        }
        const std::size_t value = type + 5;
        if (size < 0 || static_cast<std::size_t>(size) > bytes.size() - value) {
            where.error("attribute \"" + std::string(&bytes[at], name - at) + "\" declares " +
                        std::to_string(size) + " bytes, past the end of the file (" +
                        std::to_string(bytes.size()) + " bytes)");
        }
        check_attribute_value(bytes, at, name, type, value, static_cast<std::size_t>(size), where);
        at = value + static_cast<std::size_t>(size);
    }
}

}  // namespace

void check_headers(const std::vector<char>& bytes, const std::string& path,
                   const std::function<PartLimits(const std::string& part)>& limits_of) {
    PartContext where{path, "(header)"};
    if (bytes.size() < 8) where.error("too short for an OpenEXR file");
    std::int32_t magic = 0;
    std::int32_t version = 0;
    std::memcpy(&magic, bytes.data(), 4);  // little-endian hosts only, as the rest of libinsitu
    std::memcpy(&version, bytes.data() + 4, 4);
    if (magic != Imf::MAGIC) where.error("not an OpenEXR file (bad magic number)");
    const bool multi_part = Imf::isMultiPart(version);
    std::size_t at = 8;
    for (int index = 0;; ++index) {
        where.part = "(header)";
        const std::size_t end = skip_header(bytes, at, where);
        if (end == at + 1) {
            if (multi_part && index > 0) break;
            where.error("empty header");
        }
        // Every attribute size is now known to fit the file: parsing allocates at most that.
        MemoryInputStream stream(bytes, path);
        stream.seekg(at);
        Imf::Header header;
        header.readFrom(stream, version);
        if (header.hasName()) where.part = header.name();
        if (header.hasType() && header.type() != Imf::SCANLINEIMAGE) {
            where.error("part type \"" + header.type() + "\" (libinsitu writes scan lines)");
        }
        const Imath::Box2i window = header.dataWindow();
        const long long width = static_cast<long long>(window.max.x) - window.min.x + 1;
        const long long height = static_cast<long long>(window.max.y) - window.min.y + 1;
        const PartLimits limits = limits_of(header.hasName() ? header.name() : std::string());
        if (width < 1 || height < 1 || width > limits.max_width || height > limits.max_height) {
            where.error("data window " + std::to_string(width) + "x" + std::to_string(height) +
                        " is empty or larger than " + std::to_string(limits.max_width) + "x" +
                        std::to_string(limits.max_height) + " (" + limits.bound + ")");
        }
        long long channels = 0;
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it) ++channels;
        if (channels > limits.max_channels) {
            where.error(std::to_string(channels) + " channels (a libinsitu part of this kind " +
                        "has at most " + std::to_string(limits.max_channels) + ")");
        }
        // The chunk offset table (8 bytes a chunk, at least one chunk per 256 lines for every
        // compression) is in the file, so the file bounds it.
        if ((height + 255) / 256 * 8 > static_cast<long long>(bytes.size())) {
            where.error("data window height " + std::to_string(height) +
                        " needs a chunk table larger than the file (" +
                        std::to_string(bytes.size()) + " bytes)");
        }
        at = end;
        if (!multi_part) break;
    }
}

}  // namespace insitu::archive_format
