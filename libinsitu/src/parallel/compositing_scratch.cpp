#include "parallel/compositing_scratch.hpp"

#include <utility>

namespace insitu::detail {

namespace {

struct Kept {
    std::vector<Bytes> bytes;
    std::vector<std::vector<float>> floats;
    std::size_t capacity = 0;  ///< of the buffers in `bytes` and `floats`, in bytes
    RecordIndex index;
};

template <typename Buffer>
std::size_t capacity_of(const Buffer& buffer) {
    return buffer.capacity() * sizeof(typename Buffer::value_type);
}

Kept& kept() {
    thread_local Kept buffers;
    return buffers;
}

template <typename Buffer>
Buffer borrow(std::vector<Buffer>& from) {
    if (from.empty()) return Buffer{};
    Buffer buffer = std::move(from.back());
    from.pop_back();
    kept().capacity -= capacity_of(buffer);
    buffer.clear();
    return buffer;
}

template <typename Buffer>
void keep(std::vector<Buffer>& in, Buffer&& buffer) {
    const std::size_t bytes = capacity_of(buffer);
    if (bytes == 0 || kept().capacity + bytes > kKeptBytes || in.size() >= kKeptBuffers) return;
    kept().capacity += bytes;
    in.push_back(std::move(buffer));
}

}  // namespace

Bytes borrow_bytes() {
    return borrow(kept().bytes);
}

std::vector<float> borrow_floats() {
    return borrow(kept().floats);
}

void give_back(Bytes&& buffer) {
    keep(kept().bytes, std::move(buffer));
}

void give_back(std::vector<float>&& buffer) {
    keep(kept().floats, std::move(buffer));
}

void give_back(std::vector<Bytes>& buffers) {
    for (Bytes& buffer : buffers) give_back(std::move(buffer));
    buffers.clear();
}

RecordIndex& reused_record_index() {
    return kept().index;
}

}  // namespace insitu::detail
