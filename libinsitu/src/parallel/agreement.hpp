#pragma once
// Agreement in a distributed run. A rank that fails between two collectives must not skip the
// next one (the others would wait for it for ever), so local work records its failure in a
// LocalFailure and goes on, and the next agreement raises it on every rank: the same error,
// naming the rank.
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "insitu/error.hpp"
#include "insitu/parallel/communicator.hpp"

namespace insitu {

/// The first failure of this rank's local work since the last agreement.
struct LocalFailure {
    std::string message;
    ErrorKind kind = ErrorKind::none;

    bool failed() const { return !message.empty(); }
    /// Runs `work` unless an earlier step failed; records what it throws.
    template <typename Work>
    void guard(Work&& work) {
        if (!failed()) always(work);
    }
    /// Runs `work` even after a failure (a collective every rank must take part in); records
    /// what it throws unless a failure was recorded before.
    template <typename Work>
    void always(Work&& work) {
        try {
            work();
        } catch (const std::exception& error) {
            if (failed()) return;
            message = error.what();
            if (message.empty()) message = "unnamed error";
            kind = classify(std::current_exception());
        } catch (...) {
            if (failed()) return;
            message = "unknown exception";
            kind = ErrorKind::unknown;
        }
    }
    /// Raises the recorded failure here (one process: no other rank to tell).
    void raise() const {
        if (failed()) fail_as(kind, message);
    }
};

/// Raises on every rank the first failure any rank said, naming it; returns each rank's
/// `payload` otherwise (the payload every rank exchanges at that point anyway, so agreeing costs
/// no extra collective).
std::vector<Bytes> agree(Communicator& communicator, const LocalFailure& failure,
                         const Bytes& payload = {});

/// Sums `values` over the ranks in place (every rank passes as many) and raises on every rank
/// the first failure any rank said, as agree() does: one collective where nothing failed (the
/// failure travels as one more summed value; only then does agree() fetch its message).
void agree_on_sum(Communicator& communicator, const LocalFailure& failure,
                  std::vector<double>& values);

/// The ranks (", "-separated, by rank; empty: none) that do not see `folder` as a directory: a
/// collective, so every rank learns the same list.
std::string ranks_that_cannot_reach(Communicator& communicator,
                                    const std::filesystem::path& folder);

/// Doubles as the bytes a collective carries, and back (same machine representation on every
/// rank).
Bytes doubles_bytes(const std::vector<double>& values);
std::vector<double> bytes_doubles(const Bytes& bytes);

}  // namespace insitu
