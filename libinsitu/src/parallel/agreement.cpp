#include "parallel/agreement.hpp"

#include <cstdint>
#include <cstring>

namespace insitu {

namespace {

void append_bytes(Bytes& bytes, const void* data, std::size_t size) {
    const auto* begin = static_cast<const std::uint8_t*>(data);
    bytes.insert(bytes.end(), begin, begin + size);
}

// A rank's say: failed (1 byte), kind (1 byte), message length (8 bytes) and text, then the
// payload.
Bytes encode_say(const LocalFailure& failure, const Bytes& payload) {
    Bytes bytes{static_cast<std::uint8_t>(failure.failed() ? 1 : 0),
                static_cast<std::uint8_t>(failure.kind)};
    const std::uint64_t length = failure.message.size();
    append_bytes(bytes, &length, sizeof length);
    append_bytes(bytes, failure.message.data(), failure.message.size());
    append_bytes(bytes, payload.data(), payload.size());
    return bytes;
}

}  // namespace

std::vector<Bytes> agree(Communicator& communicator, const LocalFailure& failure,
                         const Bytes& payload) {
    const std::vector<Bytes> says = communicator.all_gather(encode_say(failure, payload));
    int failed_ranks = 0;
    int first = -1;
    std::vector<Bytes> payloads(says.size());
    for (std::size_t r = 0; r < says.size(); ++r) {
        const Bytes& say = says[r];
        std::uint64_t length = 0;
        if (say.size() < 2 + sizeof length) fail<Error>("agreement: rank ", r, " said nothing");
        std::memcpy(&length, &say[2], sizeof length);
        const std::size_t payload_at = 2 + sizeof length + length;
        if (payload_at > say.size()) fail<Error>("agreement: rank ", r, "'s say is cut short");
        payloads[r].assign(say.begin() + static_cast<std::ptrdiff_t>(payload_at), say.end());
        if (say[0] != 0) {
            ++failed_ranks;
            if (first < 0) first = static_cast<int>(r);
        }
    }
    if (first >= 0) {
        const Bytes& say = says[static_cast<std::size_t>(first)];
        std::uint64_t length = 0;
        std::memcpy(&length, &say[2], sizeof length);
        const std::string message(reinterpret_cast<const char*>(say.data()) + 2 + sizeof length,
                                  length);
        std::string text = "rank " + std::to_string(first) + ": " + message;
        if (failed_ranks > 1) {
            text += " (and " + std::to_string(failed_ranks - 1) + " more of the " +
                    std::to_string(says.size()) + " ranks failed)";
        }
        fail_as(static_cast<ErrorKind>(say[1]), text);
    }
    return payloads;
}

void agree_on_sum(Communicator& communicator, const LocalFailure& failure,
                  std::vector<double>& values) {
    values.push_back(failure.failed() ? 1.0 : 0.0);
    communicator.all_reduce(values, Reduction::sum);
    const bool any_failed = values.back() > 0.0;
    values.pop_back();
    if (any_failed) agree(communicator, failure);  // every rank saw the sum: all call it
}

Bytes doubles_bytes(const std::vector<double>& values) {
    Bytes bytes(values.size() * sizeof(double));
    if (!values.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
    return bytes;
}

std::vector<double> bytes_doubles(const Bytes& bytes) {
    std::vector<double> values(bytes.size() / sizeof(double));
    if (!values.empty()) std::memcpy(values.data(), bytes.data(), values.size() * sizeof(double));
    return values;
}

std::string ranks_that_cannot_reach(Communicator& communicator,
                                    const std::filesystem::path& folder) {
    std::error_code error;
    const bool reaches = std::filesystem::is_directory(folder, error);
    const std::vector<Bytes> said =
        agree(communicator, LocalFailure{}, Bytes{static_cast<std::uint8_t>(reaches ? 1 : 0)});
    std::string unreached;
    for (std::size_t r = 0; r < said.size(); ++r) {
        if (said[r] != Bytes{1}) unreached += (unreached.empty() ? "" : ", ") + std::to_string(r);
    }
    return unreached;
}

}  // namespace insitu
