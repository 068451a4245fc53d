#pragma once
// The run's statistics and errors (InstrumentStatistics, first and last error), shared by the
// simulation's thread and the writer thread under one mutex, and the line finalize() logs.
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include "insitu/error.hpp"
#include "insitu/instrument.hpp"

namespace insitu {

class RunStatistics {
public:
    /// Where warnings and errors go (one line each; the Instrument's log).
    using Log = std::function<void(const std::string&)>;
    explicit RunStatistics(Log log) : log_(std::move(log)) {}

    /// Counts an error of execute() (or one a boundary reports) or of the writer; each source
    /// logs its first error only, so a failure that repeats every step does not flood the
    /// simulation's stderr.
    void record_error(const std::string& message, ErrorKind kind, bool from_writer);
    /// A failed write: counted, described and made the run's status in one critical section, so
    /// no caller can see the count without the status.
    void record_write_failure(const std::string& message, ErrorKind kind,
                              std::exception_ptr failure);
    /// Applies `change` to the counters under the lock.
    template <typename Change>
    void update(Change&& change) {
        std::lock_guard<std::mutex> lock(mutex_);
        change(statistics_);
    }

    InstrumentStatistics snapshot() const;
    std::string last_error() const;
    std::string first_error() const;
    ErrorKind last_error_kind() const;
    /// The latest failed write (rethrown by finalize() under rethrow_errors), or null.
    std::exception_ptr write_failure() const;
    /// The last error, where writes failed since this was last asked (a distributed run tells
    /// every rank of them at the next step), else none.
    std::optional<std::string> untold_write_failure();
    /// "finalized "ARCHIVE": <statistics>; in situ ...; <budget_line>; first error: ...".
    std::string summary(const std::string& archive, const std::string& budget_line) const;

private:
    void record_error_locked(const std::string& message, ErrorKind kind, bool from_writer);

    Log log_;
    mutable std::mutex mutex_;
    InstrumentStatistics statistics_;
    std::string last_error_;
    std::string first_error_;
    ErrorKind last_error_kind_ = ErrorKind::none;
    std::exception_ptr write_failure_;
    std::int64_t write_failures_ = 0;
    std::int64_t write_failures_told_ = 0;
    bool execute_error_logged_ = false;
    bool write_error_logged_ = false;
};

}  // namespace insitu
