#pragma once
// The EXR frame codec: the proxies of one view at one step <-> one multi-part OpenEXR file, in
// memory (parts, channels and attributes: archive_format.hpp). Encoding checks what it stores;
// decoding validates every part, channel and attribute it reads, so a corrupt, truncated or
// foreign file is an IoError naming file and part, never a crash or garbage.
#include <OpenEXR/ImfCompression.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputPart.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "insitu/archive/step_record.hpp"
#include "insitu/config.hpp"
#include "insitu/error.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu::archive_format {

/// InvalidArgument naming `name` unless it is an OpenEXR compression the encoder knows.
void check_compression(const std::string& name);

struct EncodedView {
    std::string bytes;               ///< the EXR file
    std::vector<std::string> parts;  ///< part names, in file order
};

/// Whether the view's frames hold any image a part would store (a step with light fields may
/// have views with none: only their preview is stored). InvalidArgument as encode_view() for
/// images that cannot be stored.
bool holds_proxy_images(const ViewRecord& view);

/// The multi-part EXR of one view (its single and multi frames); `relative_path` names it in
/// errors. InvalidArgument for frames that cannot be stored (no images, mismatched sizes or
/// interval counts), IoError when OpenEXR fails.
EncodedView encode_view(const StepRecord& record, const ViewRecord& view,
                        StoragePrecision precision, const std::string& compression,
                        const std::string& relative_path);

/// What a decoded image part may be: the size of the view the archive recorded it for (the
/// reader takes it from the manifest's configurations), so a foreign header cannot make the
/// decoder allocate more than the view needs.
struct FrameLimits {
    int max_width = 1 << 14;
    int max_height = 1 << 14;
};

/// The frame held by the parts `parts` (all of one perspective, in file order) of the EXR
/// `bytes`; `path` names the file in errors. Every header is checked against `limits` before
/// OpenEXR sees the file (IoError naming file and part).
ProxyFrame decode_frame(const std::vector<char>& bytes, const std::string& path,
                        const std::vector<std::string>& parts, bool multi_perspective,
                        const FrameLimits& limits = {});

// ---------------------------------------------------------------------------------------------
// The OpenEXR plumbing this codec shares with the light-field codec (light_field_exr.hpp).

/// The OpenEXR compression `name` names; InvalidArgument naming it otherwise.
Imf::Compression parse_compression(const std::string& name);

/// zlib level of "zip" and "zips" parts. The encoding runs on the simulation's core (an MPI rank
/// is bound to one), so it is chosen for time: zlib's levels 1 to 3 share its fast deflate, and
/// level 2 encoded as fast as 1 for slightly fewer bytes, and took markedly less time than
/// OpenEXR's default 4 for a few more bytes (issue 18; bench/RESULTS.md, "zlib level 2 for zip
/// parts"; bench_overhead measures it in situ). The level is not stored in the file: readers
/// need nothing.
inline constexpr int kZipCompressionLevel = 2;

/// Collects the encoded EXR in memory, so that the bytes are checksummed and written by the same
/// durable path as every other file (errors such as EFBIG or ENOSPC come back with errno).
class MemoryOutputStream : public Imf::OStream {
public:
    explicit MemoryOutputStream(const std::string& name) : Imf::OStream(name.c_str()) {}
    void write(const char c[], int n) override {
        if (position_ + n > bytes_.size()) bytes_.resize(position_ + n);
        std::memcpy(&bytes_[position_], c, static_cast<std::size_t>(n));
        position_ += static_cast<std::size_t>(n);
    }
    std::uint64_t tellp() override { return position_; }
    void seekp(std::uint64_t position) override { position_ = position; }
    std::string& bytes() { return bytes_; }

private:
    std::string bytes_;
    std::size_t position_ = 0;
};

/// Lets OpenEXR parse a file already read (and checksummed) into memory.
class MemoryInputStream : public Imf::IStream {
public:
    MemoryInputStream(const std::vector<char>& bytes, const std::string& name)
        : Imf::IStream(name.c_str()), bytes_(bytes) {}
    bool read(char c[], int n) override {
        if (n < 0 || position_ > bytes_.size() || bytes_.size() - position_ < std::size_t(n)) {
            throw std::runtime_error("unexpected end of file at byte " + std::to_string(position_));
        }
        std::memcpy(c, bytes_.data() + position_, static_cast<std::size_t>(n));
        position_ += static_cast<std::size_t>(n);
        return position_ < bytes_.size();
    }
    std::uint64_t tellg() override { return position_; }
    void seekg(std::uint64_t position) override { position_ = position; }

private:
    const std::vector<char>& bytes_;
    std::uint64_t position_ = 0;
};

/// Where an error happened, for messages: file and part.
struct PartContext {
    const std::string& file;
    std::string part;
    [[noreturn]] void error(const std::string& what) const {
        fail<IoError>("\"", file, "\" part \"", part, "\": ", what);
    }
};

/// The string attribute `name` of a part, or its JSON; IoError naming file, part and attribute
/// when it is missing or not JSON.
const std::string& string_attribute(const Imf::Header& header, const char* name,
                                    const PartContext& where);
nlohmann::json json_attribute(const Imf::Header& header, const char* name,
                              const PartContext& where);

/// Reads the channels `names` of one part into one image (channel c = names[c]), converting
/// HALF and UINT channels to float, in one pass over the part's compressed chunks.
Image read_channels(Imf::InputPart& part, const std::vector<std::string>& names,
                    const PartContext& where);
/// Channels [first, first + count) of an interleaved image.
Image channel_range(const Image& all, int first, int count);

/// What one part of a file may declare.
struct PartLimits {
    long long max_width = 0;
    long long max_height = 0;
    long long max_channels = 0;
    std::string bound;  ///< what sets the size bound, for messages ("the view")
};
/// Refuses, before OpenEXR allocates what a header declares (issue 19: a 1 373-byte file asked
/// for 531 MB), data windows and channel lists larger than `limits_of(part name)` allows, parts
/// that are not scan-line images, attribute types libinsitu never writes, and chunk tables the
/// file is too small to hold. IoError naming `path` and the part.
void check_headers(const std::vector<char>& bytes, const std::string& path,
                   const std::function<PartLimits(const std::string& part)>& limits_of);

}  // namespace insitu::archive_format
