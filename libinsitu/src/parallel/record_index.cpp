#include "parallel/record_index.hpp"

#include "insitu/error.hpp"

namespace insitu::detail {

void append(Bytes& bytes, const void* data, std::size_t size) {
    const auto* begin = static_cast<const std::uint8_t*>(data);
    bytes.insert(bytes.end(), begin, begin + size);
}

std::size_t fragments_in(const Image& fragment, int channels, std::int64_t begin,
                         std::int64_t end) {
    std::size_t count = 0;
    for (std::int64_t pixel = begin; pixel < end; ++pixel) {
        if (fragment.pixels[pixel * channels] >= 0.0f) ++count;
    }
    return count;
}

void index_records(const std::vector<Bytes>& messages, int record_floats, std::int64_t begin,
                   std::int64_t end, RecordIndex& index) {
    const std::size_t stride = sizeof(std::uint32_t) + record_floats * sizeof(float);
    index.starts.assign(static_cast<std::size_t>(end - begin) + 1, 0);
    std::size_t count = 0;
    for (const Bytes& message : messages) {
        for_each_record(message, stride, [&](std::uint32_t pixel, std::size_t) {
            if (pixel < begin || pixel >= end) {
                fail<Error>("compositing: a record for pixel ", pixel, " outside the tile [", begin,
                            ", ", end, ")");
            }
            ++index.starts[pixel - begin + 1];
            ++count;
        });
    }
    for (std::size_t p = 1; p < index.starts.size(); ++p) index.starts[p] += index.starts[p - 1];
    index.refs.resize(count);
    std::vector<std::uint32_t>& next = index.next;
    next.assign(index.starts.begin(), index.starts.end() - 1);
    for (const Bytes& message : messages) {
        for (std::size_t at = 0; at < message.size(); at += stride) {
            RecordRef ref;
            std::memcpy(&ref.pixel, &message[at], sizeof ref.pixel);
            ref.values = &message[at + sizeof ref.pixel];
            std::memcpy(&ref.first_index, ref.values, sizeof(float));
            index.refs[next[ref.pixel - begin]++] = ref;
        }
    }
    // A pixel has at most one record per rank: insertion sort of short runs.
    for (std::size_t p = 0; p + 1 < index.starts.size(); ++p) {
        RecordRef* first = index.refs.data() + index.starts[p];
        RecordRef* last = index.refs.data() + index.starts[p + 1];
        for (RecordRef* i = first + 1; i < last; ++i) {
            const RecordRef moving = *i;
            RecordRef* j = i;
            for (; j > first && (j - 1)->first_index > moving.first_index; --j) *j = *(j - 1);
            *j = moving;
        }
    }
}

}  // namespace insitu::detail
