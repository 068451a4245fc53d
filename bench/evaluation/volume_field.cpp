#include "volume_field.hpp"

#include <zfp.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "insitu/error.hpp"
#include "median_time.hpp"

namespace insitu::evaluation {

std::string ZfpSetting::label() const {
    char text[48];
    std::snprintf(text, sizeof text, "%s %g", mode == Mode::accuracy ? "accuracy" : "rate", value);
    return text;
}

std::vector<ZfpSetting> zfp_settings(bool smoke) {
    using Mode = ZfpSetting::Mode;
    if (smoke) return {{Mode::accuracy, 1e-2}, {Mode::accuracy, 1e-3}, {Mode::rate, 1.0}};
    std::vector<ZfpSetting> settings;
    for (const double r : {3e-1, 1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 1e-4}) {
        settings.push_back({Mode::accuracy, r});
    }
    for (const double rate : {0.25, 0.5, 1.0, 2.0, 4.0, 8.0})
        settings.push_back({Mode::rate, rate});
    return settings;
}

namespace {

struct ZfpDeleter {
    void operator()(zfp_field* field) const { zfp_field_free(field); }
    void operator()(zfp_stream* stream) const { zfp_stream_close(stream); }
    void operator()(bitstream* stream) const { stream_close(stream); }
};

/// One ZFP stream over `buffer` for the scene's dims, set to `setting`.
struct Codec {
    std::unique_ptr<zfp_stream, ZfpDeleter> zfp{zfp_stream_open(nullptr)};
    std::unique_ptr<bitstream, ZfpDeleter> bits;
};

}  // namespace

CompressedField compress_field(const Scene& scene, const ZfpSetting& setting, int repeats) {
    if (!(setting.value > 0.0) || !std::isfinite(setting.value)) {
        fail<InvalidArgument>("ZFP ", setting.label(), ": needs a positive finite value");
    }
    const Index3 dims = scene.volume.dims;
    CompressedField result;
    result.decoded = scene.volume;
    // ZFP reads through a non-const pointer; it does not write the input.
    std::vector<float> input = scene.volume.values;
    std::unique_ptr<zfp_field, ZfpDeleter> in(
        zfp_field_3d(input.data(), zfp_type_float, static_cast<std::size_t>(dims[0]),
                     static_cast<std::size_t>(dims[1]), static_cast<std::size_t>(dims[2])));
    std::unique_ptr<zfp_field, ZfpDeleter> out(zfp_field_3d(
        result.decoded.values.data(), zfp_type_float, static_cast<std::size_t>(dims[0]),
        static_cast<std::size_t>(dims[1]), static_cast<std::size_t>(dims[2])));
    Codec codec;
    if (setting.mode == ZfpSetting::Mode::accuracy) {
        result.tolerance = setting.value * (scene.value_max - scene.value_min);
        zfp_stream_set_accuracy(codec.zfp.get(), result.tolerance);
    } else {
        zfp_stream_set_rate(codec.zfp.get(), setting.value, zfp_type_float, 3, zfp_false);
    }
    std::vector<unsigned char> buffer(zfp_stream_maximum_size(codec.zfp.get(), in.get()));
    codec.bits.reset(stream_open(buffer.data(), buffer.size()));
    zfp_stream_set_bit_stream(codec.zfp.get(), codec.bits.get());
    std::size_t bytes = 0;
    bool header = true;
    result.compress_ms = bench::median_ms(repeats, [&] {
        zfp_stream_rewind(codec.zfp.get());
        header = zfp_write_header(codec.zfp.get(), in.get(), ZFP_HEADER_FULL) != 0 && header;
        bytes = zfp_compress(codec.zfp.get(), in.get());  // the stream's end: header included
    });
    if (!header || bytes == 0) fail<IoError>("ZFP ", setting.label(), ": compression failed");
    result.bytes = bytes;
    bool decoded = true;
    result.decompress_ms = bench::median_ms(repeats, [&] {
        zfp_stream_rewind(codec.zfp.get());
        decoded = zfp_read_header(codec.zfp.get(), out.get(), ZFP_HEADER_FULL) != 0 &&
                  zfp_decompress(codec.zfp.get(), out.get()) != 0 && decoded;
    });
    if (!decoded) fail<IoError>("ZFP ", setting.label(), ": decompression failed");
    return result;
}

}  // namespace insitu::evaluation
