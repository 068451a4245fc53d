#pragma once
// The records the ranks exchange to composite (compositing.cpp): each the pixel's index (uint32)
// then a fixed number of floats, the first the index of the record's first sample (its place
// along the ray). How they are counted, packed and found again by pixel, in ray order.
#include <cstdint>
#include <cstring>
#include <vector>

#include "insitu/core/image.hpp"
#include "insitu/error.hpp"
#include "insitu/parallel/communicator.hpp"

namespace insitu::detail {

void append(Bytes& bytes, const void* data, std::size_t size);

/// How many of the pixels [begin, end) have a fragment (first index >= 0) in a fragment image
/// of `channels` floats per pixel: messages are sized once, not grown.
std::size_t fragments_in(const Image& fragment, int channels, std::int64_t begin, std::int64_t end);

/// Calls visit(pixel, at) for each record of `message` (each `record_bytes`, its pixel's uint32
/// index first; `at` its offset in the message), after checking the message holds whole records.
template <typename Visit>
void for_each_record(const Bytes& message, std::size_t record_bytes, Visit visit) {
    if (message.size() % record_bytes != 0) {
        fail<Error>("compositing: a message of ", message.size(),
                    " bytes is not a whole number of ", record_bytes, "-byte records");
    }
    for (std::size_t at = 0; at < message.size(); at += record_bytes) {
        std::uint32_t pixel = 0;
        std::memcpy(&pixel, &message[at], sizeof pixel);
        visit(pixel, at);
    }
}

/// One received record: its pixel, the index of its first sample, and where its floats are in
/// the message (read with memcpy: floats are not read through a byte pointer).
struct RecordRef {
    std::uint32_t pixel;
    float first_index;
    const std::uint8_t* values;
};

inline void load_record(const RecordRef& ref, int record_floats, float* into) {
    std::memcpy(into, ref.values, static_cast<std::size_t>(record_floats) * sizeof(float));
}

/// The records of every message for the pixels [begin, end), grouped by pixel (a counting sort:
/// one pass, no allocation per record) and, within a pixel, in ray order: by the index of their
/// first sample. Pixel p's records are refs[starts[p - begin], starts[p - begin + 1]). The
/// messages may hold their records in any order (radix-k's rounds concatenate them).
struct RecordIndex {
    std::vector<RecordRef> refs;
    std::vector<std::uint32_t> starts;
    std::vector<std::uint32_t> next;  ///< scratch of the sort
};

/// Fills `index` (what it held is replaced; its capacity is reused: compositing_scratch.hpp).
void index_records(const std::vector<Bytes>& messages, int record_floats, std::int64_t begin,
                   std::int64_t end, RecordIndex& index);

}  // namespace insitu::detail
