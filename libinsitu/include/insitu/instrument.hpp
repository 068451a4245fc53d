#pragma once
// insitu::Instrument — what a simulation holds. Once per timestep it calls execute() with
// zero-copy Field views; the proxies are computed, copied off the simulation's memory, and handed
// to a writer thread with a bounded queue; execute() returns then. finalize() drains the queue.
//
// The simulation is sacred: no exception leaves execute() or finalize() unless the Instrument was
// made with `rethrow_errors` (for tests). Failures become a Status, are logged once to stderr,
// and the run goes on; last_error() says what happened.
#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "insitu/config.hpp"
#include "insitu/error.hpp"
#include "insitu/field.hpp"

namespace insitu {

class Communicator;

enum class Status {
    ok,            ///< proxies computed and queued (or written)
    not_selected,  ///< the cadence skipped this step
    dropped,       ///< writer queue full with when_full = drop: this step was not stored
    error,         ///< see last_error(); nothing already written was lost
};
std::string to_string(Status status);
std::ostream& operator<<(std::ostream& out, Status status);

struct InstrumentStatistics {
    std::int64_t steps_executed = 0;  ///< execute() calls that computed proxies
    std::int64_t steps_written = 0;
    std::int64_t steps_dropped = 0;
    /// Steps skipped because the archive held them already (a restarted run replaying them).
    std::int64_t steps_replayed = 0;
    /// Failures of execute(), of the writer, and those a boundary reports (report_error).
    std::int64_t errors = 0;
    std::uint64_t bytes_written = 0;
    double compute_seconds = 0.0;  ///< in execute(), computing proxies
    double blocked_seconds = 0.0;  ///< in execute(), waiting for room in the writer queue
    double write_seconds = 0.0;    ///< on the writer thread
    /// Distributed only: in execute(), agreeing on bounds, ranges and errors and compositing the
    /// partial images (part of compute_seconds).
    double composite_seconds = 0.0;
    /// Wall time inside execute() (every call, whatever its status): what the simulation waited.
    double execute_seconds = 0.0;
    /// Wall time between one execute() returning and the next being called: the simulation's
    /// own work, against which the in-situ share is stated.
    double simulation_seconds = 0.0;
    /// NaN/Inf samples met in the visualised fields, summed over steps (treated as empty space).
    std::int64_t nonfinite_samples = 0;
};
std::ostream& operator<<(std::ostream& out, const InstrumentStatistics& statistics);

struct InstrumentOptions {
    /// Let exceptions out of execute()/finalize() instead of turning them into Status (tests).
    bool rethrow_errors = false;
    /// Print warnings and the finalize() summary to stderr (under a communicator: rank 0 only).
    bool log = true;
    /// The simulation's ranks (insitu/mpi.hpp makes one of an MPI_Comm). When set, the
    /// Instrument is distributed: each rank's execute() passes its own block of every field and
    /// every rank calls the constructor, execute() and finalize() collectively, with the same
    /// step and time. Bounds, value range, layers, intervals and histogram are agreed over all
    /// ranks; each rank marches the samples it owns, the partial images are composited sort-last
    /// (direct send over image tiles, insitu/parallel/compositing.hpp) and rank 0 alone writes
    /// the archive. A failure on any rank makes every rank return error for that step, with the
    /// same message naming the rank. Blocks: see insitu/parallel/decomposition.hpp.
    std::shared_ptr<Communicator> communicator;
};
std::ostream& operator<<(std::ostream& out, const InstrumentOptions& options);

class Instrument {
public:
    /// Validates the configuration and opens (or continues) the archive. Unlike execute(), the
    /// constructor throws: a simulation checks its configuration once, at start-up.
    explicit Instrument(InstrumentConfig config, InstrumentOptions options = {});
    static std::unique_ptr<Instrument> from_json_file(const std::string& path,
                                                      InstrumentOptions options = {});
    static std::unique_ptr<Instrument> from_json_text(const std::string& text,
                                                      InstrumentOptions options = {});
    ~Instrument();  ///< finalize()s if the simulation did not

    Instrument(const Instrument&) = delete;
    Instrument& operator=(const Instrument&) = delete;

    /// One timestep: fields are matched by name against the configuration's "fields"; every
    /// configured field is visualised, each with its views, into one archive. Several Fields of
    /// one name are the blocks (tiles) of that field and are joined (join_blocks). Checks, in
    /// order: not finalized; `step` in [0, 2^53 - 1] (what the JSON manifest holds exactly),
    /// `time` finite (JSON has no NaN/Inf), `step` greater than every step executed before
    /// (else error naming it, nothing written); a step the archive already holds (a restarted
    /// run replaying it) is skipped, not_selected, with one notice per run; the cadence (else
    /// not_selected, nothing computed, no field needed); every configured field present (else
    /// error naming it); the blocks join; the values within float32, which the renderers
    /// sample. Then computes the proxies and preview of every view and queues them; with the
    /// queue full it waits (when_full = block, timed in blocked_seconds) or returns dropped.
    /// The Fields are not referenced after execute() returns.
    Status execute(std::int64_t step, double time, const std::vector<Field>& fields);
    /// Whether execute(step, ...) would compute proxies: not finalized, after the last step,
    /// selected by the cadence and not already archived (a step a restarted run replays is
    /// counted in steps_replayed, with the one notice). Fields need only be made then.
    bool selects(std::int64_t step) const;
    /// Counts a failure met at a boundary before execute() (a C API set_field, say) as an error
    /// of the run: logged like execute()'s first error, kept as the first root cause.
    void report_error(const std::string& message, ErrorKind kind);
    /// Drains the writer queue and stops the writer; later execute() calls return error.
    /// Returns error when a write failed during the run (last_error() says which); calling it
    /// again does nothing and returns ok.
    Status finalize();

    InstrumentStatistics statistics() const;
    /// The most recent error message (empty if none).
    std::string last_error() const;
    /// The first error of the run (empty if none): the root cause the later ones often follow.
    std::string first_error() const;
    /// The kind of that error (ErrorKind::none if none), so boundaries such as the C API can map
    /// it to a code without reading the message.
    ErrorKind last_error_kind() const;
    const InstrumentConfig& config() const;
    /// Unknown configuration keys found at construction (also logged).
    const std::vector<std::string>& unknown_keys() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace insitu
