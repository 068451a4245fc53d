#include "run_statistics.hpp"

#include <iomanip>
#include <ostream>
#include <sstream>

namespace insitu {

// The instrument's printers: Status, InstrumentOptions, and the summary line's statistics
// (finalize's log).
std::string to_string(Status status) {
    switch (status) {
        case Status::ok:
            return "ok";
        case Status::not_selected:
            return "not_selected";
        case Status::dropped:
            return "dropped";
        case Status::error:
            return "error";
    }
    return "unknown";
}

std::ostream& operator<<(std::ostream& out, Status status) {
    return out << to_string(status);
}

std::ostream& operator<<(std::ostream& out, const InstrumentOptions& options) {
    return out << "InstrumentOptions{rethrow_errors " << std::boolalpha << options.rethrow_errors
               << ", log " << options.log << std::noboolalpha << "}";
}

std::ostream& operator<<(std::ostream& out, const InstrumentStatistics& s) {
    std::ostringstream line;
    line << std::fixed << std::setprecision(3) << "executed " << s.steps_executed << ", written "
         << s.steps_written << ", dropped " << s.steps_dropped << ", errors " << s.errors << ", "
         << s.bytes_written << " bytes, compute " << s.compute_seconds << " s, blocked "
         << s.blocked_seconds << " s, writing " << s.write_seconds << " s";
    if (s.steps_replayed > 0) line << ", replayed " << s.steps_replayed << " (skipped)";
    if (s.nonfinite_samples > 0) line << ", " << s.nonfinite_samples << " NaN/Inf samples";
    if (s.composite_seconds > 0.0) line << ", compositing " << s.composite_seconds << " s";
    return out << line.str();
}

void RunStatistics::record_error(const std::string& message, ErrorKind kind, bool from_writer) {
    std::lock_guard<std::mutex> lock(mutex_);
    record_error_locked(message, kind, from_writer);
}

void RunStatistics::record_write_failure(const std::string& message, ErrorKind kind,
                                         std::exception_ptr failure) {
    std::lock_guard<std::mutex> lock(mutex_);
    record_error_locked(message, kind, /*from_writer=*/true);
    write_failure_ = std::move(failure);
    ++write_failures_;
}

void RunStatistics::record_error_locked(const std::string& message, ErrorKind kind,
                                        bool from_writer) {
    ++statistics_.errors;
    if (first_error_.empty()) first_error_ = message;
    last_error_ = message;
    last_error_kind_ = kind;
    bool& logged = from_writer ? write_error_logged_ : execute_error_logged_;
    if (!logged) {
        logged = true;
        log_("error: " + message +
             " (the run goes on; later errors are counted, not logged, see last_error())");
    }
}

InstrumentStatistics RunStatistics::snapshot() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return statistics_;
}

std::string RunStatistics::last_error() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_error_;
}

std::string RunStatistics::first_error() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return first_error_;
}

ErrorKind RunStatistics::last_error_kind() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_error_kind_;
}

std::exception_ptr RunStatistics::write_failure() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return write_failure_;
}

std::optional<std::string> RunStatistics::untold_write_failure() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (write_failures_ <= write_failures_told_) return std::nullopt;
    write_failures_told_ = write_failures_;
    return last_error_;
}

std::string RunStatistics::summary(const std::string& archive,
                                   const std::string& budget_line) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::ostringstream summary;
    summary << "finalized \"" << archive << "\": " << statistics_;
    // The cost a user can see and bound (issue 18): the share of the run's wall time the
    // simulation spent waiting in execute(), beside its own time between the calls.
    const InstrumentStatistics& s = statistics_;
    const double wall = s.execute_seconds + s.simulation_seconds;
    if (wall > 0.0) {
        summary << std::fixed << std::setprecision(3) << "; in situ " << s.execute_seconds
                << " s inside execute, " << std::setprecision(1) << 100.0 * s.execute_seconds / wall
                << " % of " << std::setprecision(3) << wall
                << " s wall since the first call (simulation " << s.simulation_seconds
                << " s between calls; writer " << s.write_seconds << " s on its own thread)";
    }
    if (!budget_line.empty()) summary << "; " << budget_line;
    if (!first_error_.empty()) summary << "; first error: " << first_error_;
    if (!last_error_.empty() && last_error_ != first_error_) {
        summary << "; last error: " << last_error_;
    }
    return summary.str();
}

}  // namespace insitu
