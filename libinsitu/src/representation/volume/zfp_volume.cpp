#include "representation/volume/zfp_volume.hpp"

#include <zfp.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "insitu/error.hpp"

namespace insitu::archive_format {

namespace {

std::int64_t sample_count(Index3 dims) {
    return dims[0] * dims[1] * dims[2];
}

// ZFP's handles, closed however the scope is left.
struct ZfpStreamCloser {
    void operator()(zfp_stream* stream) const { zfp_stream_close(stream); }
};
struct ZfpFieldCloser {
    void operator()(zfp_field* field) const { zfp_field_free(field); }
};
struct BitStreamCloser {
    void operator()(bitstream* stream) const { stream_close(stream); }
};
using ZfpStream = std::unique_ptr<zfp_stream, ZfpStreamCloser>;
using ZfpField = std::unique_ptr<zfp_field, ZfpFieldCloser>;
using BitStream = std::unique_ptr<bitstream, BitStreamCloser>;

/// ZFP compresses blocks of 4^3 samples; a non-finite sample is given the mean of its block's
/// finite ones, so the block stays as smooth as its data, or `fallback` where it has none.
void fill_nonfinite(std::vector<float>& values, Index3 dims, float fallback) {
    for (std::int64_t bz = 0; bz < dims[2]; bz += 4) {
        for (std::int64_t by = 0; by < dims[1]; by += 4) {
            for (std::int64_t bx = 0; bx < dims[0]; bx += 4) {
                double sum = 0.0;
                int finite = 0;
                std::vector<std::int64_t> holes;
                for (std::int64_t z = bz; z < std::min(bz + 4, dims[2]); ++z) {
                    for (std::int64_t y = by; y < std::min(by + 4, dims[1]); ++y) {
                        for (std::int64_t x = bx; x < std::min(bx + 4, dims[0]); ++x) {
                            const std::int64_t i = x + dims[0] * (y + dims[1] * z);
                            if (std::isfinite(values[i])) {
                                sum += values[i];
                                ++finite;
                            } else {
                                holes.push_back(i);
                            }
                        }
                    }
                }
                const float fill = finite > 0 ? static_cast<float>(sum / finite) : fallback;
                for (const std::int64_t i : holes) values[i] = fill;
            }
        }
    }
}

std::string deflate(const std::vector<unsigned char>& bytes) {
    uLongf size = compressBound(static_cast<uLong>(bytes.size()));
    std::string out(size, '\0');
    if (compress2(reinterpret_cast<Bytef*>(out.data()), &size, bytes.data(),
                  static_cast<uLong>(bytes.size()), Z_BEST_COMPRESSION) != Z_OK) {
        fail<Error>("compressed field: zlib could not compress the non-finite mask");
    }
    out.resize(size);
    return out;
}

void check_parameters(const ZfpParameters& parameters) {
    if (parameters.mode == VolumeMode::accuracy &&
        !(parameters.tolerance > 0.0 && std::isfinite(parameters.tolerance))) {
        fail<InvalidArgument>("compressed field: tolerance ", parameters.tolerance,
                              " (field units, must be finite and > 0)");
    }
    if (parameters.mode == VolumeMode::rate &&
        !(parameters.rate >= 0.5 && parameters.rate <= 32.0)) {
        fail<InvalidArgument>("compressed field: rate ", parameters.rate,
                              " (bits per value, must be in [0.5, 32])");
    }
    if (parameters.threads < 1) {
        fail<InvalidArgument>("compressed field: threads ", parameters.threads, " (must be >= 1)");
    }
}

/// ZFP trusts a header's bits per block: a non-empty block spends 1 + 8 bits on its exponent
/// before its budget is subtracted, so a header whose budget is smaller underflows that unsigned
/// subtraction and ZFP reads far past any buffer (found by the fuzzer). Only the modes this
/// writer uses are accepted, and a rate no smaller than its smallest (0.5 bits per value).
void check_block_budget(const zfp_stream* zfp, const std::string& path) {
    const zfp_mode mode = zfp_stream_compression_mode(zfp);
    unsigned int min_bits = 0;
    unsigned int max_bits = 0;
    unsigned int max_precision = 0;
    int min_exponent = 0;
    zfp_stream_params(zfp, &min_bits, &max_bits, &max_precision, &min_exponent);
    const unsigned int smallest_block = 32;  // 0.5 bits per value x 4^3 values
    if ((mode != zfp_mode_fixed_accuracy && mode != zfp_mode_fixed_rate) || min_bits > max_bits ||
        max_bits < smallest_block) {
        fail<IoError>("\"", path, "\": the ZFP header asks for a mode this archive never writes (",
                      min_bits, " to ", max_bits, " bits per block; corrupt)");
    }
}

void check_dims(Index3 dims, const std::string& where) {
    for (const std::int64_t n : dims) {
        if (n < 1 || n > kMaxVolumeBlockSamples) {
            fail<InvalidArgument>(where, ": dimensions ", dims[0], "x", dims[1], "x", dims[2],
                                  " (each must be >= 1)");
        }
    }
    if (sample_count(dims) > kMaxVolumeBlockSamples) {
        fail<InvalidArgument>(where, ": ", dims[0], "x", dims[1], "x", dims[2],
                              " samples are more than a block may hold (", kMaxVolumeBlockSamples,
                              ")");
    }
}

/// A zero-padded copy of `bytes` of at least `size` bytes, in whole 64-bit words as ZFP's bit
/// stream reads them: reads past the data find zeros inside the buffer, never past it.
std::vector<std::uint64_t> padded_words(const std::vector<char>& bytes, std::size_t size) {
    const std::size_t words =
        (std::max(size, bytes.size()) + 2 * sizeof(std::uint64_t) - 1) / sizeof(std::uint64_t);
    std::vector<std::uint64_t> buffer(words, 0);
    std::copy(bytes.begin(), bytes.end(), reinterpret_cast<char*>(buffer.data()));
    return buffer;
}

/// The mask's bits; IoError unless it inflates to exactly one bit per sample with `nonfinite`
/// set.
std::vector<unsigned char> inflate_mask(const std::vector<char>& mask, std::int64_t samples,
                                        std::int64_t nonfinite, const std::string& path) {
    std::vector<unsigned char> bits(static_cast<std::size_t>((samples + 7) / 8));
    uLongf size = static_cast<uLongf>(bits.size());
    if (uncompress(bits.data(), &size, reinterpret_cast<const Bytef*>(mask.data()),
                   static_cast<uLong>(mask.size())) != Z_OK ||
        size != bits.size()) {
        fail<IoError>("\"", path, "\": the non-finite mask is corrupt or not ", samples, " bits");
    }
    std::int64_t marked = 0;
    for (std::int64_t i = 0; i < samples; ++i) marked += (bits[i / 8] >> (i % 8)) & 1;
    if (marked != nonfinite) {
        fail<IoError>("\"", path, "\": the non-finite mask marks ", marked,
                      " samples, the manifest records ", nonfinite);
    }
    return bits;
}

}  // namespace

EncodedVolumeBlock encode_volume_block(const float* values, Index3 dims,
                                       const ZfpParameters& parameters) {
    check_dims(dims, "compressed field");
    check_parameters(parameters);
    const std::int64_t samples = sample_count(dims);
    std::vector<float> filled(values, values + samples);
    EncodedVolumeBlock encoded;
    std::vector<unsigned char> bits(static_cast<std::size_t>((samples + 7) / 8), 0);
    double finite_sum = 0.0;
    for (std::int64_t i = 0; i < samples; ++i) {
        if (std::isfinite(filled[i])) {
            finite_sum += filled[i];
        } else {
            bits[i / 8] |= static_cast<unsigned char>(1u << (i % 8));
            ++encoded.nonfinite;
        }
    }
    if (encoded.nonfinite > 0) {
        const std::int64_t finite = samples - encoded.nonfinite;
        fill_nonfinite(
            filled, dims,
            finite > 0 ? static_cast<float>(finite_sum / static_cast<double>(finite)) : 0.0f);
        encoded.mask = deflate(bits);
    }

    const ZfpField field(zfp_field_3d(filled.data(), zfp_type_float, static_cast<size_t>(dims[0]),
                                      static_cast<size_t>(dims[1]), static_cast<size_t>(dims[2])));
    const ZfpStream zfp(zfp_stream_open(nullptr));
    if (parameters.mode == VolumeMode::accuracy) {
        zfp_stream_set_accuracy(zfp.get(), parameters.tolerance);
    } else {
        zfp_stream_set_rate(zfp.get(), parameters.rate, zfp_type_float, 3, zfp_false);
    }
    encoded.stream.assign(zfp_stream_maximum_size(zfp.get(), field.get()), '\0');
    const BitStream bits_out(stream_open(encoded.stream.data(), encoded.stream.size()));
    zfp_stream_set_bit_stream(zfp.get(), bits_out.get());
    zfp_stream_rewind(zfp.get());
    // OpenMP compresses chunks of blocks in parallel (the writer's thread then waits on them,
    // never the simulation's).
    if (parameters.threads > 1 && zfp_stream_set_execution(zfp.get(), zfp_exec_omp)) {
        zfp_stream_set_omp_threads(zfp.get(), static_cast<unsigned int>(parameters.threads));
    }
    if (zfp_write_header(zfp.get(), field.get(), ZFP_HEADER_FULL) == 0) {
        fail<Error>("compressed field: ZFP could not write its header");
    }
    const std::size_t size = zfp_compress(zfp.get(), field.get());
    if (size == 0) fail<Error>("compressed field: ZFP could not compress the block");
    encoded.stream.resize(size);
    return encoded;
}

std::vector<float> decode_volume_block(const std::vector<char>& stream,
                                       const std::vector<char>& mask, Index3 dims,
                                       std::int64_t nonfinite, const std::string& path) {
    try {
        check_dims(dims, "\"" + path + "\"");
    } catch (const InvalidArgument& error) {
        fail<IoError>(error.what());
    }
    const std::int64_t samples = sample_count(dims);
    if (nonfinite < 0 || nonfinite > samples || (nonfinite == 0) != mask.empty()) {
        fail<IoError>("\"", path, "\": ", nonfinite, " non-finite samples with a mask of ",
                      mask.size(), " bytes");
    }
    // The header first, from a padded copy (a file shorter than a header reads zeros).
    std::vector<std::uint64_t> buffer = padded_words(stream, 0);
    BitStream bits(stream_open(buffer.data(), buffer.size() * sizeof(std::uint64_t)));
    const ZfpStream zfp(zfp_stream_open(bits.get()));
    const ZfpField field(zfp_field_alloc());
    zfp_stream_rewind(zfp.get());
    if (zfp_read_header(zfp.get(), field.get(), ZFP_HEADER_FULL) == 0) {
        fail<IoError>("\"", path, "\": not a ZFP stream with a full header");
    }
    size_t header_dims[3] = {0, 0, 0};
    zfp_field_size(field.get(), header_dims);
    if (field->type != zfp_type_float || zfp_field_dimensionality(field.get()) != 3 ||
        static_cast<std::int64_t>(header_dims[0]) != dims[0] ||
        static_cast<std::int64_t>(header_dims[1]) != dims[1] ||
        static_cast<std::int64_t>(header_dims[2]) != dims[2]) {
        fail<IoError>("\"", path, "\": the ZFP header declares another grid than the manifest's ",
                      dims[0], "x", dims[1], "x", dims[2], " floats");
    }
    check_block_budget(zfp.get(), path);
    const std::size_t largest = zfp_stream_maximum_size(zfp.get(), field.get());
    if (largest == 0 || stream.size() > largest) {
        fail<IoError>("\"", path, "\": ", stream.size(),
                      " bytes, more than any ZFP stream of its header (corrupt)");
    }
    // Decoded from a buffer as large as the largest stream its header allows, so that no
    // corruption of the stream can make ZFP read past it.
    buffer = padded_words(stream, largest);
    bits.reset(stream_open(buffer.data(), buffer.size() * sizeof(std::uint64_t)));
    zfp_stream_set_bit_stream(zfp.get(), bits.get());
    zfp_stream_rewind(zfp.get());
    zfp_read_header(zfp.get(), field.get(), ZFP_HEADER_FULL);
    std::vector<float> values(static_cast<std::size_t>(samples));
    zfp_field_set_pointer(field.get(), values.data());
    if (zfp_decompress(zfp.get(), field.get()) == 0 ||
        zfp_stream_compressed_size(zfp.get()) > stream.size()) {
        fail<IoError>("\"", path, "\": the ZFP stream is truncated or corrupt");
    }
    if (nonfinite > 0) {
        const std::vector<unsigned char> marked = inflate_mask(mask, samples, nonfinite, path);
        for (std::int64_t i = 0; i < samples; ++i) {
            if ((marked[i / 8] >> (i % 8)) & 1) values[i] = std::nanf("");
        }
    }
    return values;
}

}  // namespace insitu::archive_format
