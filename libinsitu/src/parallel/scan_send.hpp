#pragma once
// Direct send with answers (light_field_compositing.cpp): like direct_send.hpp, every rank sends
// the records of tile k's pixels to rank k, which folds each pixel's records in ray order; but
// the fold also answers every record (what lies in front of that block), and the answers go back
// to the ranks that sent them. The folded tiles, where the fold makes outputs, are gathered at the
// root as direct_send gathers them.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <exception>
#include <functional>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/parallel/communicator.hpp"
#include "parallel/direct_send.hpp"

namespace insitu::detail {

/// Floats per record (after the pixel index; the first is the record's first sample index, the
/// ray order), per answer and per folded pixel.
struct ScanShape {
    int record = 0;
    int reply = 0;
    int outputs = 0;
};

/// Writes this rank's record of `pixel`; false where it has none.
using ScanPack = std::function<bool(std::int64_t pixel, float* record)>;
/// Folds one pixel's records (ray order) into its outputs, and answers each record.
using ScanFold = std::function<void(const std::vector<const float*>& records,
                                    const std::vector<float*>& replies, float* outputs)>;
/// Takes the root's folded pixels [begin, end).
using ScanUnpack = std::function<void(std::int64_t begin, std::int64_t end, const float* values)>;

namespace scan {

inline Bytes float_bytes(const std::vector<float>& values) {
    Bytes bytes(values.size() * sizeof(float));
    if (!bytes.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
    return bytes;
}

inline std::vector<float> bytes_floats(const Bytes& bytes, std::size_t stride_floats) {
    if (bytes.size() % (stride_floats * sizeof(float)) != 0) {
        fail<Error>("compositing: a message of ", bytes.size(), " bytes is not a whole number of ",
                    stride_floats * sizeof(float), "-byte records");
    }
    std::vector<float> values(bytes.size() / sizeof(float));
    if (!values.empty()) std::memcpy(values.data(), bytes.data(), bytes.size());
    return values;
}

inline std::uint32_t pixel_of(const float* entry) {
    std::uint32_t pixel = 0;
    std::memcpy(&pixel, entry, sizeof pixel);
    return pixel;
}

// Folds the tile [begin, end) from every rank's records (pixel bits, then the record), in place
// of the answers `replies` (one vector per rank, a reply per record it sent).
inline std::vector<float> fold_tile(const std::vector<std::vector<float>>& messages,
                                    const ScanShape& shape, std::int64_t begin, std::int64_t end,
                                    const std::vector<float>& identity, const ScanFold& fold,
                                    std::vector<std::vector<float>>& replies) {
    const std::size_t stride = static_cast<std::size_t>(shape.record) + 1;
    std::vector<float> tile;
    tile.reserve(static_cast<std::size_t>(end - begin) * identity.size());
    std::vector<std::size_t> cursor(messages.size(), 0);
    replies.assign(messages.size(), {});
    for (std::size_t k = 0; k < messages.size(); ++k) {
        replies[k].assign(messages[k].size() / stride * shape.reply, 0.0f);
    }
    std::vector<std::pair<const float*, float*>> pixel_records;
    std::vector<const float*> records;
    std::vector<float*> answers;
    for (std::int64_t pixel = begin; pixel < end; ++pixel) {
        pixel_records.clear();
        for (std::size_t k = 0; k < messages.size(); ++k) {
            const std::size_t at = cursor[k] * stride;
            if (at >= messages[k].size() || pixel_of(&messages[k][at]) != pixel) continue;
            pixel_records.emplace_back(&messages[k][at + 1], &replies[k][cursor[k] * shape.reply]);
            ++cursor[k];
        }
        const std::size_t first = tile.size();
        tile.insert(tile.end(), identity.begin(), identity.end());
        if (pixel_records.empty()) continue;
        std::sort(pixel_records.begin(), pixel_records.end(),
                  [](const auto& a, const auto& b) { return a.first[0] < b.first[0]; });
        records.clear();
        answers.clear();
        for (const auto& [record, answer] : pixel_records) {
            records.push_back(record);
            answers.push_back(answer);
        }
        fold(records, answers, tile.data() + first);
    }
    for (std::size_t k = 0; k < messages.size(); ++k) {
        if (cursor[k] * stride != messages[k].size()) {
            fail<Error>("compositing: rank ", k, " sent records outside the tile [", begin, ", ",
                        end, ") or out of order");
        }
    }
    return tile;
}

}  // namespace scan

/// The exchange: returns this rank's answers by pixel (`reply` floats each; `no_reply` where it
/// sent no record). The root's folded pixels go to `unpack` (outputs > 0; `identity` is the
/// outputs of a pixel without records). A rank whose own work fails sends nothing, takes part
/// in every exchange and throws once they are done.
inline std::vector<float> scan_send(Communicator& communicator, std::int64_t pixels,
                                    const ScanShape& shape, int root, const ScanPack& pack,
                                    const ScanFold& fold, const std::vector<float>& identity,
                                    const std::vector<float>& no_reply, const ScanUnpack& unpack) {
    const int ranks = communicator.size();
    const int me = communicator.rank();
    if (pixels >= std::int64_t{1} << 32) fail<InvalidArgument>("compositing: ", pixels, " pixels");
    FirstFailure local;
    const std::size_t stride = static_cast<std::size_t>(shape.record) + 1;
    std::vector<Bytes> to_each(static_cast<std::size_t>(ranks));
    std::vector<std::vector<std::uint32_t>> sent(static_cast<std::size_t>(ranks));
    local([&] {
        std::vector<float> entry(stride);
        for (int k = 0; k < ranks; ++k) {
            std::vector<float> message;
            for (std::int64_t p = tile_begin(pixels, ranks, k);
                 p < tile_begin(pixels, ranks, k + 1); ++p) {
                if (!pack(p, entry.data() + 1)) continue;
                const auto pixel = static_cast<std::uint32_t>(p);
                std::memcpy(entry.data(), &pixel, sizeof pixel);
                message.insert(message.end(), entry.begin(), entry.end());
                sent[k].push_back(pixel);
            }
            to_each[k] = scan::float_bytes(message);
        }
    });
    if (local.failure) {
        to_each.assign(static_cast<std::size_t>(ranks), Bytes{});
        sent.assign(static_cast<std::size_t>(ranks), {});
    }
    std::vector<Bytes> received = communicator.all_to_all(to_each);
    received[me] = to_each[me];
    const std::int64_t begin = tile_begin(pixels, ranks, me);
    const std::int64_t end = tile_begin(pixels, ranks, me + 1);
    std::vector<float> tile;
    std::vector<std::vector<float>> replies;
    local([&] {
        std::vector<std::vector<float>> messages;
        for (const Bytes& message : received)
            messages.push_back(scan::bytes_floats(message, stride));
        tile = scan::fold_tile(messages, shape, begin, end, identity, fold, replies);
    });
    std::vector<float> mine(static_cast<std::size_t>(pixels) * shape.reply);
    for (std::int64_t p = 0; p < pixels && shape.reply > 0; ++p) {
        std::copy(no_reply.begin(), no_reply.end(), mine.begin() + p * shape.reply);
    }
    replies.resize(static_cast<std::size_t>(ranks));
    std::vector<Bytes> answers_out;
    for (const std::vector<float>& reply : replies) answers_out.push_back(scan::float_bytes(reply));
    const std::vector<Bytes> answers =
        shape.reply > 0 ? communicator.all_to_all(answers_out) : std::vector<Bytes>{};
    if (shape.reply > 0)
        local([&] {
            for (int k = 0; k < ranks; ++k) {
                const Bytes& bytes = k == me ? answers_out[me] : answers[k];
                const std::vector<float> values = scan::bytes_floats(bytes, shape.reply);
                if (values.size() != sent[k].size() * shape.reply) {
                    fail<Error>("compositing: rank ", k, " answered ", values.size() / shape.reply,
                                " of ", sent[k].size(), " records");
                }
                for (std::size_t r = 0; r < sent[k].size(); ++r) {
                    std::copy(values.begin() + r * shape.reply,
                              values.begin() + (r + 1) * shape.reply,
                              mine.begin() + sent[k][r] * shape.reply);
                }
            }
        });
    if (shape.outputs > 0) {
        gather_folded_tiles(communicator, std::move(tile), equal_tiles(pixels, ranks),
                            shape.outputs, root, local, unpack);
    }
    local.rethrow();
    return mine;
}

}  // namespace insitu::detail
