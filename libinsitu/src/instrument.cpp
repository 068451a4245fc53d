#include "insitu/instrument.hpp"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <exception>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "archive/exr_frame.hpp"
#include "archive/light_field_exr.hpp"
#include "archive/writer_thread.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/core/camera.hpp"
#include "insitu/core/check.hpp"
#include "insitu/core/histogram.hpp"
#include "insitu/core/layers.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/colour_model.hpp"
#include "insitu/explore/light_field_reconstruction.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "insitu/explore/view_synthesis.hpp"
#include "insitu/parallel/compositing.hpp"
#include "insitu/parallel/decomposition.hpp"
#include "insitu/render/distortion_camera.hpp"
#include "insitu/render/light_field_capture.hpp"
#include "insitu/render/proxy_renderer.hpp"

namespace insitu {

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

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Largest step number the manifest holds exactly (see Impl::execute).
constexpr std::int64_t kMaxStep = (std::int64_t{1} << 53) - 1;

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string joined_names(const std::vector<Field>& fields) {
    std::string names;
    for (const Field& field : fields) names += (names.empty() ? "" : ", ") + field.name();
    return names.empty() ? "none" : names;
}

// Agreement in a distributed run. A rank that fails between two collectives must not skip the
// next one (the others would wait for it for ever), so local work records its failure here and
// goes on, and the next agreement raises it on every rank: the same error, naming the rank.
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
};

void append_bytes(Bytes& bytes, const void* data, std::size_t size) {
    const auto* begin = static_cast<const std::uint8_t*>(data);
    bytes.insert(bytes.end(), begin, begin + size);
}

// A rank's say: failed (1 byte), kind (1 byte), message length (8 bytes) and text, then the
// payload every rank exchanges at that point anyway (so agreeing costs no extra collective).
Bytes encode_say(const LocalFailure& failure, const Bytes& payload) {
    Bytes bytes{static_cast<std::uint8_t>(failure.failed() ? 1 : 0),
                static_cast<std::uint8_t>(failure.kind)};
    const std::uint64_t length = failure.message.size();
    append_bytes(bytes, &length, sizeof length);
    append_bytes(bytes, failure.message.data(), failure.message.size());
    append_bytes(bytes, payload.data(), payload.size());
    return bytes;
}

// Raises on every rank the first failure any rank said; returns each rank's payload otherwise.
std::vector<Bytes> agree(Communicator& communicator, const LocalFailure& failure,
                         const Bytes& payload = {}) {
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

}  // namespace

struct Instrument::Impl {
    InstrumentConfig config;
    InstrumentOptions options;
    std::vector<std::string> unknown_keys;

    // Touched by execute()/finalize() only, i.e. by the simulation's thread.
    std::unique_ptr<ProxyRenderer> renderer;
    std::set<std::int64_t> archived_steps;  ///< steps the archive held when it was opened
    std::optional<std::int64_t> last_step;  ///< the last step execute() accepted
    bool finalized = false;
    bool nonfinite_reported = false;
    bool replay_reported = false;
    std::vector<float> joined_blocks;  ///< storage of a field joined from several blocks
    /// When the last execute() returned: the simulation's own time runs from there.
    std::optional<Clock::time_point> last_return;

    // Touched by the writer thread only (after construction); rank 0's alone when distributed.
    std::unique_ptr<ArchiveWriter> archive;

    /// The ranks of a distributed run (InstrumentOptions::communicator), or null.
    std::shared_ptr<Communicator> communicator;
    /// Write failures (under `mutex`) and how many of them the ranks have been told of.
    std::int64_t write_failures = 0;
    std::int64_t write_failures_told = 0;
    /// Whether this process writes (and logs): rank 0, or the only process.
    bool writes() const { return !communicator || communicator->rank() == 0; }

    // Shared between the two threads, under `mutex`.
    mutable std::mutex mutex;
    std::condition_variable work_ready;  ///< a record was queued, or stop
    std::condition_variable room;        ///< a write finished: the queue has room
    std::deque<StepRecord> queue;
    int writing = 0;  ///< records taken off the queue and still being written
    bool stopping = false;
    InstrumentStatistics statistics;
    std::string last_error;
    std::string first_error;
    ErrorKind last_error_kind = ErrorKind::none;
    std::exception_ptr write_failure;  ///< the latest failed write, rethrown by finalize()
    bool execute_error_logged = false;
    bool write_error_logged = false;

    std::thread writer;

    void log(const std::string& line) const {
        // In a distributed run every rank meets the same warnings: rank 0 says them once.
        if (options.log && writes()) std::cerr << "insitu: " << one_line(line) << std::endl;
    }

    /// Counts an error of execute() or of the writer; each source logs its first error only, so a
    /// failure that repeats every step does not flood the simulation's stderr.
    void record_error(const std::string& message, ErrorKind kind, bool from_writer) {
        std::lock_guard<std::mutex> lock(mutex);
        record_error_locked(message, kind, from_writer);
    }
    /// record_error() with `mutex` held: a writer failure is counted, described and made the
    /// run's status in one critical section, so no caller can see the count without the status.
    void record_error_locked(const std::string& message, ErrorKind kind, bool from_writer) {
        ++statistics.errors;
        if (first_error.empty()) first_error = message;
        last_error = message;
        last_error_kind = kind;
        bool& logged = from_writer ? write_error_logged : execute_error_logged;
        if (!logged) {
            logged = true;
            log("error: " + message +
                " (the run goes on; later errors are counted, not logged, see last_error())");
        }
    }

    /// Keeps the configuration's unknown keys ("strict": false) and logs refuse_unknown_keys's
    /// warning about them.
    void adopt_unknown_keys(std::vector<std::string> keys, const std::string& warning) {
        unknown_keys = std::move(keys);
        if (!warning.empty()) log("warning: " + warning);
    }

    bool selects(std::int64_t step) const {
        return !finalized && (!last_step || step > *last_step) && config.selects(step) &&
               archived_steps.count(step) == 0;
    }

    Status execute(std::int64_t step, double time, const std::vector<Field>& fields);
    /// The checks of execute() that need no field (step, time, order, finalize).
    void check_step(std::int64_t step, double time) const;
    /// Whether a checked step is skipped (already archived, counted and noticed once; or not
    /// selected by the cadence); notes it as the last step then.
    bool skips(std::int64_t step);
    /// The step's record: every configured field planned and rendered (on rank 0, composited;
    /// elsewhere the record is not kept). Adds the time spent agreeing and compositing.
    StepRecord compute(std::int64_t step, double time, const std::vector<Field>& fields,
                       double& composite_seconds);
    /// What the views of one field are rendered from: the uploaded field, or this rank's block
    /// of it, and what was agreed about the whole grid.
    struct FieldPlan {
        std::string name;
        Bounds bounds;  ///< the whole grid's
        std::vector<double> isovalues;
        IntervalSet intervals = IntervalSet::uniform(0.0, 1.0, 1);
        bool has_block = true;  ///< false: a rank that owns nothing of the field
        /// The whole grid's values at this step (stored with the step, and what "auto" spans).
        FieldSummaryRecord summary;
        /// The configured function, or for "auto" default_transfer_function(summary.histogram).
        TransferFunction transfer_function{std::vector<ControlPoint>{{0.0, {0, 0, 0, 0}}}};
        /// With a "budget": what it archives the field with at this step.
        std::optional<BudgetRecord> budget;
    };
    /// The error budget's state of one field: its choice, the check that made it, and the
    /// field's histogram then (values that move are checked again at once).
    struct BudgetState {
        BudgetRecord choice;
        std::int64_t archived_since_check = 0;
        ValueHistogram histogram;
        int checks = 0;
    };
    std::map<std::string, BudgetState> budget_state;
    /// The budget's choice for the field of `plan` at this step (checking when one is due),
    /// applied to the plan's intervals where the budget chooses them.
    BudgetRecord apply_budget(FieldPlan& plan);
    /// Measures every candidate on the field's first view and picks the cheapest that meets
    /// the budget (see BudgetConfig).
    BudgetRecord check_budget(const FieldPlan& plan) const;
    /// The budget's ground truth: the proxies' step, marched on to T = 0 as the proxies are.
    RenderSettings budget_truth_settings() const {
        RenderSettings settings;
        settings.step_voxels = config.step_voxels;
        settings.early_termination_opacity = 1.0;
        return settings;
    }
    /// Whether the field's views fit the colour model: the training functions apply to it
    /// (InstrumentConfig::trains), the model is enabled and the attenuation it maps is stored.
    bool fits_colour_model(const std::string& field) const {
        return config.trains(field) && !config.training_transfer_functions.empty() &&
               config.colour_model.enabled && config.proxies.attenuation;
    }
    /// A view the budget measures: the stored one (offset 0) or a turn of it in azimuth
    /// (Camera::reorbit), at the asked size, with the held-out edit's ground truth in it.
    struct BudgetView {
        double azimuth_offset_deg = 0.0;
        Camera camera;
        Image truth;
    };
    /// The light field's camera count and map size (BudgetConfig::chooses_light_field), with the
    /// views' choice made: measured in the budget's views, within what the views left of the
    /// bytes and time.
    BudgetRecord::LightFieldChoice check_light_field_budget(
        const FieldPlan& plan, const BudgetRecord& views,
        const std::vector<BudgetView>& targets) const;
    /// The colour model's K (BudgetConfig::chooses_colour_model), with the views' choice made:
    /// the held-out edit as the Explorer colours it (the model), fitted on the training pairs of
    /// `source` (the stored view at the size chosen), in the budget's views.
    BudgetRecord::ColourModelChoice check_colour_model_budget(
        const FieldPlan& plan, const BudgetRecord& views, const Camera& source,
        const std::vector<BudgetView>& targets) const;
    /// "budget: field "v" 8 uniform intervals chosen, half chosen, full size chosen at 3
    /// check(s); last measured 41.2 dB (asked >= 40) in its worst of 3 views, azimuth +20 deg
    /// (stored view 44.0 dB), ...; the check took 35.0 ms".
    std::string budget_summary() const {
        const BudgetConfig& budget = *config.budget;
        std::ostringstream out;
        out << std::fixed << std::setprecision(1) << "budget: ";
        if (budget_state.empty()) out << "no step checked";
        const double share = 1.0 / static_cast<double>(config.fields.size());
        const char* separator = "";
        for (const auto& [field, state] : budget_state) {
            const BudgetRecord& c = state.choice;
            out << separator << "field \"" << field << "\" " << c.intervals << " "
                << to_string(c.interval_mode) << " intervals"
                << (budget.chooses_intervals ? " chosen" : " (given)");
            if (c.precision) {
                out << ", " << to_string(*c.precision)
                    << (budget.chooses_precision ? " chosen" : " (given)");
            }
            if (budget.chooses_size) {
                out << ", "
                    << (c.size_divisor == 1
                            ? std::string("full size")
                            : "1/" + std::to_string(c.size_divisor) + " of each side")
                    << " chosen";
            }
            out << " at " << state.checks << " check(s); last measured " << c.psnr_db << " dB";
            if (budget.psnr_db) out << " (asked >= " << *budget.psnr_db << ")";
            // The PSNR is the least over the views: say which, and the stored view's own.
            if (c.views.size() > 1) {
                const auto worst = std::min_element(
                    c.views.begin(), c.views.end(),
                    [](const auto& a, const auto& b) { return a.psnr_db < b.psnr_db; });
                out << " in its worst of " << c.views.size() << " views, azimuth " << std::showpos
                    << worst->azimuth_offset_deg << std::noshowpos << " deg (stored view "
                    << c.views.front().psnr_db << " dB)";
            }
            out << ", " << c.bytes / 1e6 << " MB";
            if (budget.bytes_per_step)
                out << " (<= " << share * *budget.bytes_per_step / 1e6 << ")";
            out << ", " << c.milliseconds << " ms per step";
            if (budget.ms_per_step) out << " (<= " << share * *budget.ms_per_step << ")";
            out << (c.met ? ", met" : ", NOT met: the closest candidate");
            if (const auto& light_field = c.light_field) {
                out << "; light field " << light_field->cameras << " cameras at "
                    << light_field->size << "^2 chosen, " << light_field->psnr_db << " dB, "
                    << light_field->bytes / 1e6 << " MB, " << light_field->milliseconds
                    << " ms per step"
                    << (light_field->met ? ", met" : ", NOT met: the closest candidate");
            }
            if (const auto& model = c.colour_model) {
                out << "; colour model K = " << model->clusters << " chosen, " << model->psnr_db
                    << " dB, fitted in " << model->milliseconds << " ms"
                    << (model->met ? ", met" : ", NOT met: the closest candidate");
            }
            out << "; the check took " << c.check_milliseconds << " ms";
            separator = "; ";
        }
        return out.str();
    }
    /// The function a field is rendered with at this step (the plan's summary is filled in).
    TransferFunction transfer_function_for(const std::string& name,
                                           const ValueHistogram& histogram) const {
        const std::optional<TransferFunction>& configured = config.transfer_function_of(name);
        return configured ? *configured : default_transfer_function(histogram);
    }
    /// Uploads one field and chooses its layers and intervals (one process).
    FieldPlan plan_field(const Field& field, std::int64_t step);
    /// The same for this rank's block (or none) of a distributed field, agreed over the ranks.
    FieldPlan plan_distributed_field(const std::string& name,
                                     const std::vector<const Field*>& blocks, std::int64_t step,
                                     double& composite_seconds);
    /// Checks the value range and reports NaN/Inf samples (once per run).
    void check_range(const std::string& name, const ValueRange& range, std::int64_t step);
    /// Renders the views of one planned field into `record`, numbering them from
    /// record.views.size(); distributed, every pass is composited at rank 0.
    void compute_field(const FieldPlan& plan, StepRecord& record, double& composite_seconds);
    Status execute_distributed(std::int64_t step, double time, const std::vector<Field>& fields);
    Status enqueue(StepRecord record, double compute_seconds);
    void writer_loop();
    Status finalize();
    /// Opens (or continues) the archive and notes the steps it holds.
    void open_archive();
    /// The constructor's work with a communicator: every rank validates and makes its device,
    /// rank 0 opens the archive, and all agree (one failure fails every rank) and learn the
    /// archived steps.
    void open_distributed(InstrumentConfig distributed_config);
};

void Instrument::Impl::open_archive() {
    const std::string& path = config.archive;
    std::error_code ignored;
    const bool continuing = fs::exists(fs::path(path) / "manifest.json", ignored);
    try {
        archive = std::make_unique<ArchiveWriter>(config);
    } catch (const fs::filesystem_error& error) {
        fail<IoError>("cannot open archive \"", path, "\": ", error.what());
    }
    if (continuing) {
        // execute() rejects these up front, so a replayed step fails at once and synchronously
        // instead of later on the writer thread.
        const ArchiveReader existing(path);
        for (std::int64_t step : existing.steps()) archived_steps.insert(step);
    }
}

void Instrument::Impl::open_distributed(InstrumentConfig distributed_config) {
    LocalFailure failure;
    failure.guard([&] {
        distributed_config.validate();
        if (distributed_config.budget) {
            fail<InvalidArgument>(
                "\"budget\": an error budget is measured against a ground truth of the whole "
                "field, which one process of a distributed run does not hold; give the settings "
                "themselves, or measure them in a run without a communicator");
        }
        if (distributed_config.light_field) {
            fail<InvalidArgument>(
                "\"light_field\": light fields are not composited across ranks (their segments "
                "and first hits depend on the opacity in front of a block, which the block "
                "cannot know); capture them in a run without a communicator");
        }
    });
    config = std::move(distributed_config);
    failure.guard([&] { renderer = std::make_unique<ProxyRenderer>(); });
    std::vector<double> archived;
    if (writes()) {
        failure.guard([&] {
            open_archive();
            for (std::int64_t step : archived_steps) archived.push_back(static_cast<double>(step));
        });
    }
    // Steps are below 2^53 (execute() checks), so doubles carry them exactly.
    const std::vector<Bytes> said = agree(*communicator, failure, doubles_bytes(archived));
    for (double step : bytes_doubles(said.at(0))) {
        archived_steps.insert(static_cast<std::int64_t>(step));
    }
    if (writes()) writer = std::thread(&Impl::writer_loop, this);
}

Status Instrument::Impl::execute_distributed(std::int64_t step, double time,
                                             const std::vector<Field>& fields) {
    Communicator& ranks = *communicator;
    double composite_seconds = 0.0;
    LocalFailure failure;
    failure.guard([&] { check_step(step, time); });
    // Rank 0 tells the others of writes that failed since the last step: the run's status is
    // the same on every rank.
    if (writes() && !failure.failed()) {
        std::lock_guard<std::mutex> lock(mutex);
        if (write_failures > write_failures_told) {
            write_failures_told = write_failures;
            failure.message = "an earlier step could not be written (" + last_error +
                              "); this step was not computed";
            failure.kind = ErrorKind::io;
        }
    }
    auto start = Clock::now();
    const std::vector<Bytes> said =
        agree(ranks, failure, doubles_bytes({static_cast<double>(step), time}));
    composite_seconds += seconds_since(start);
    const std::vector<double> reference = bytes_doubles(said.at(0));
    for (std::size_t r = 1; r < said.size(); ++r) {
        const std::vector<double> values = bytes_doubles(said[r]);
        if (values != reference) {
            fail<InvalidArgument>("ranks disagree on the step: rank ", r, " passed step ",
                                  values.at(0), " at time ", values.at(1), ", rank 0 step ",
                                  reference.at(0), " at time ", reference.at(1),
                                  " (every rank calls execute with the same step and time)");
        }
    }
    // The same on every rank: the archived steps and the cadence are.
    if (skips(step)) return Status::not_selected;

    const auto compute_start = Clock::now();
    StepRecord record = compute(step, time, fields, composite_seconds);
    const double compute_seconds = seconds_since(compute_start);
    last_step = step;
    {
        std::lock_guard<std::mutex> lock(mutex);
        statistics.composite_seconds += composite_seconds;
    }
    Status status = Status::ok;
    LocalFailure failure_to_queue;
    failure_to_queue.guard([&] {
        if (writes()) {
            status = enqueue(std::move(record), compute_seconds);
        } else {
            std::lock_guard<std::mutex> lock(mutex);
            ++statistics.steps_executed;
            statistics.compute_seconds += compute_seconds;
        }
    });
    // Every rank returns rank 0's status: a step dropped there is dropped for all.
    Bytes verdict{static_cast<std::uint8_t>(status)};
    ranks.broadcast(verdict, 0);
    agree(ranks, failure_to_queue);
    return static_cast<Status>(verdict.at(0));
}

bool Instrument::Impl::skips(std::int64_t step) {
    // A restarted simulation replays steps an earlier run already archived: those are kept as
    // they are ("on_existing": "append") and skipped, with one notice.
    if (archived_steps.count(step) != 0) {
        last_step = step;
        {
            std::lock_guard<std::mutex> lock(mutex);
            ++statistics.steps_replayed;
        }
        if (!replay_reported) {
            replay_reported = true;
            log("notice: step " + std::to_string(step) + " is already in archive \"" +
                config.archive +
                "\" (a restarted run replaying it): archived steps are skipped, counted in "
                "statistics (\"on_existing\": \"replace\" starts the archive anew)");
        }
        return true;
    }
    if (!config.selects(step)) {
        last_step = step;
        return true;
    }
    return false;
}

void Instrument::Impl::check_step(std::int64_t step, double time) const {
    if (finalized) fail<StateError>("execute(step ", step, ") after finalize()");
    // Archive files are named by step number; a negative one has no name.
    if (step < 0) fail<InvalidArgument>("step ", step, ": step numbers must be >= 0");
    // The manifest is JSON, which the viewer's JavaScript reads as doubles: beyond 2^53 two
    // steps could read back as one, and the reader refuses a manifest with a repeated step.
    if (step > kMaxStep) {
        fail<InvalidArgument>("step ", step, ": step numbers must be <= ", kMaxStep,
                              " (2^53 - 1, the largest integer every JSON reader holds exactly)");
    }
    // JSON has no NaN or Inf: such a time would be written as null and the manifest, with every
    // step already in it, would no longer read.
    if (!std::isfinite(time)) {
        fail<InvalidArgument>("step ", step, ": time = ", time, " (must be finite)");
    }
    if (last_step && step <= *last_step) {
        if (step == *last_step) fail<InvalidArgument>("step ", step, ": duplicate step number");
        fail<InvalidArgument>("step ", step, ": not after the previous step ", *last_step,
                              " (step numbers must increase)");
    }
}

Status Instrument::Impl::execute(std::int64_t step, double time, const std::vector<Field>& fields) {
    if (communicator) return execute_distributed(step, time, fields);
    check_step(step, time);
    if (skips(step)) return Status::not_selected;
    for (const std::string& name : config.fields) {
        const bool present = std::any_of(fields.begin(), fields.end(),
                                         [&](const Field& f) { return f.name() == name; });
        if (!present) {
            fail<InvalidArgument>("step ", step, ": field \"", name, "\" missing (got ",
                                  joined_names(fields), ")");
        }
    }

    const auto start = Clock::now();
    double composite_seconds = 0.0;  // none without a communicator
    StepRecord record = compute(step, time, fields, composite_seconds);
    const double compute_seconds = seconds_since(start);
    // From here the step number is used, even if the queue drops the step.
    last_step = step;
    return enqueue(std::move(record), compute_seconds);
}

StepRecord Instrument::Impl::compute(std::int64_t step, double time,
                                     const std::vector<Field>& fields, double& composite_seconds) {
    StepRecord record;
    record.step = step;
    record.time = time;
    record.field = config.fields.front();
    for (const std::string& name : config.fields) {
        std::vector<const Field*> blocks;
        for (const Field& field : fields) {
            if (field.name() == name) blocks.push_back(&field);
        }
        if (communicator) {
            // A rank may own nothing of a field: it passes no block, and marches nothing.
            compute_field(plan_distributed_field(name, blocks, step, composite_seconds), record,
                          composite_seconds);
        } else if (blocks.size() == 1) {
            // One block is marched where it lies (zero-copy up to the upload); tiles are joined.
            compute_field(plan_field(*blocks.front(), step), record, composite_seconds);
        } else {
            compute_field(plan_field(join_blocks(blocks, joined_blocks), step), record,
                          composite_seconds);
        }
    }
    return record;
}

void Instrument::Impl::check_range(const std::string& name, const ValueRange& range,
                                   std::int64_t step) {
    // The renderers sample float32: a finite double beyond its range becomes Inf there, and the
    // intervals and layers chosen from the range would describe values no sample holds.
    const double float_max = std::numeric_limits<float>::max();
    if (range.min < -float_max || range.max > float_max) {
        fail<InvalidArgument>("step ", step, ": field \"", name, "\" has values in [", range.min,
                              ", ", range.max, "], beyond the float32 range +-", float_max,
                              " the renderers sample in");
    }
    if (range.nonfinite_count > 0) {
        {
            std::lock_guard<std::mutex> lock(mutex);
            statistics.nonfinite_samples += range.nonfinite_count;
        }
        if (!nonfinite_reported) {
            nonfinite_reported = true;
            log("warning: step " + std::to_string(step) + ": field \"" + name + "\" has " +
                std::to_string(range.nonfinite_count) +
                " NaN/Inf samples, treated as empty space (counted in statistics, reported "
                "once)");
        }
    }
}

Instrument::Impl::FieldPlan Instrument::Impl::plan_field(const Field& field, std::int64_t step) {
    // The one read of the simulation's memory: the upload packs the interior into the renderer's
    // host staging vector and the device buffer; everything below reads those copies.
    renderer->upload(field);
    const DeviceVolume& volume = renderer->volume();
    check_range(field.name(), volume.range, step);
    // Layers and intervals come from this step's data: "model no more than a scene needs".
    FieldPlan plan;
    plan.name = field.name();
    plan.bounds = volume.bounds;
    plan.summary.field = plan.name;
    plan.summary.nonfinite_samples = volume.range.nonfinite_count;
    plan.summary.histogram =
        volume.range.empty()
            ? ValueHistogram::of({}, 0.0, 0.0)
            : ValueHistogram::of(volume.host_values, volume.range.min, volume.range.max);
    plan.transfer_function = transfer_function_for(plan.name, plan.summary.histogram);
    const std::optional<std::vector<double>>& layers = config.layers_of(field.name());
    plan.isovalues =
        layers ? *layers : renderer->choose_layers(plan.transfer_function, config.max_auto_layers);
    // A budget that chooses the intervals sets them itself (apply_budget).
    if (!config.budget || !config.budget->chooses_intervals) {
        plan.intervals = renderer->choose_intervals(config.interval_count, config.interval_mode,
                                                    &plan.transfer_function);
    }
    if (config.budget) plan.budget = apply_budget(plan);
    return plan;
}

namespace {

/// The budget's held-out edit: the run's function with every control point's opacity halved
/// in extinction, a' = 1 - (1 - a)^0.5 (the law opacity edits follow), colours kept.
TransferFunction halved_opacity(const TransferFunction& tf) {
    std::vector<ControlPoint> points = tf.rows().front().points;
    for (ControlPoint& point : points) {
        point.rgba.a = 1.0f - std::sqrt(std::max(0.0f, 1.0f - point.rgba.a));
    }
    return TransferFunction(points, tf.unit_length());
}

/// The held-out edit's attenuation (`scales`) in a measured view, from the stored view's proxies
/// as the Explorer makes it: estimated in place for the stored view, first synthesised into the
/// view turned by `turn_deg` from `source` for a turned one (`turned_view`).
Image held_out_attenuation(const ProxyFrame& stored, const Camera& source, bool turned_view,
                           double turn_deg, const std::vector<double>& scales) {
    if (!turned_view) {
        return estimate_attenuation(stored.attenuation, stored.mean_depth, nullptr, scales);
    }
    const SynthesisedAttenuation turned = synthesise_attenuation(
        stored, source.reorbit(source.azimuth_deg() + turn_deg, source.elevation_deg()));
    return estimate_attenuation(turned.attenuation, turned.mean_depth, nullptr, scales);
}

/// PSNR of `shown` against `truth` as a display shows it: enlarged bilinearly to the truth's
/// size where the budget stored the view smaller.
double psnr_as_shown(const Image& truth, Image shown) {
    if (shown.width != truth.width || shown.height != truth.height) {
        shown = resize_bilinear(shown, truth.width, truth.height);
    }
    return psnr_rgb_db(truth, shown);
}

/// Whether a measured PSNR meets the accuracy the budget asks (any, where it asks none).
bool accurate_enough(const BudgetConfig& budget, double psnr_db) {
    return !budget.psnr_db || psnr_db >= *budget.psnr_db;
}

/// The budget's rule over the candidates it measured (BudgetConfig): with an accuracy asked, the
/// cheapest that meets every limit; else (or where none does) the cheapest affordable one within
/// kBudgetPsnrTolerance of the most accurate affordable one; else the cheapest. `measured` is
/// not empty.
template <typename Candidate, typename Affordable, typename Accurate, typename Cheaper>
const Candidate* choose_candidate(const std::vector<Candidate>& measured, bool accuracy_asked,
                                  const Affordable& affordable, const Accurate& accurate,
                                  const Cheaper& cheaper) {
    const Candidate* chosen = nullptr;
    for (const Candidate& c : measured) {
        if (accuracy_asked && affordable(c) && accurate(c) && (!chosen || cheaper(c, *chosen))) {
            chosen = &c;
        }
    }
    if (!chosen) {
        double best_db = -std::numeric_limits<double>::infinity();
        for (const Candidate& c : measured) {
            if (affordable(c)) best_db = std::max(best_db, c.psnr_db);
        }
        for (const Candidate& c : measured) {
            if (affordable(c) && c.psnr_db >= best_db - kBudgetPsnrTolerance &&
                (!chosen || cheaper(c, *chosen))) {
                chosen = &c;
            }
        }
    }
    if (!chosen) {
        for (const Candidate& c : measured) {
            if (!chosen || cheaper(c, *chosen)) chosen = &c;
        }
    }
    return chosen;
}

}  // namespace

BudgetRecord Instrument::Impl::apply_budget(FieldPlan& plan) {
    const BudgetConfig& budget = *config.budget;
    const auto [found, fresh] = budget_state.try_emplace(plan.name);
    BudgetState& state = found->second;
    const bool moved =
        !fresh && histogram_distance(state.histogram, plan.summary.histogram) > kBudgetMovedShare;
    const bool due = fresh || moved || state.archived_since_check >= budget.check_every;
    if (due) {
        state.choice = check_budget(plan);
        state.histogram = plan.summary.histogram;
        state.archived_since_check = 0;
        ++state.checks;
    }
    ++state.archived_since_check;
    BudgetRecord choice = state.choice;
    choice.checked = due;
    if (budget.chooses_intervals) {
        plan.intervals = renderer->choose_intervals(choice.intervals, choice.interval_mode,
                                                    &plan.transfer_function);
    }
    return choice;
}

BudgetRecord Instrument::Impl::check_budget(const FieldPlan& plan) const {
    const auto check_start = Clock::now();
    const BudgetConfig& budget = *config.budget;
    const std::vector<ViewConfig>& views = config.views_of(plan.name);
    const ViewConfig& view = views.front();
    const Camera camera = Camera::orbit(view.orbit, plan.bounds);
    const double view_count = static_cast<double>(views.size());
    // The fields share the step's bytes and time evenly.
    const double share = 1.0 / static_cast<double>(config.fields.size());
    const TransferFunction held_out = halved_opacity(plan.transfer_function);
    const RenderSettings truth_settings = budget_truth_settings();
    // The measured views' ground truths, once per check: the stored view, then each rotation
    // (turned in azimuth as the Explorer turns a view, Camera::reorbit).
    std::vector<BudgetView> measured_views;
    const auto truth_start = Clock::now();
    measured_views.push_back(
        {0.0, camera, renderer->render_ground_truth(camera, held_out, truth_settings).rgba});
    // The step's preview (the stored view's rendering) is one such pass per view.
    const double preview_ms = 1e3 * seconds_since(truth_start);
    for (const double rotation : budget.rotations_deg) {
        const Camera turned =
            camera.reorbit(camera.azimuth_deg() + rotation, camera.elevation_deg());
        measured_views.push_back(
            {rotation, turned,
             renderer->render_ground_truth(turned, held_out, truth_settings).rgba});
    }

    // The sizes measured: the asked one, and each smaller one whose sides stay at least
    // kBudgetMinViewSide. A smaller size's stored-view rendering (its bytes, its preview's time)
    // is one more ground-truth pass at that size.
    struct CandidateSize {
        int divisor = 1;
        Camera camera;
        Image rendering;
        double preview_ms = 0.0;
    };
    std::vector<CandidateSize> sizes;
    for (const int divisor : kBudgetSizeDivisors) {
        OrbitView orbit = view.orbit;
        orbit.width /= divisor;
        orbit.height /= divisor;
        if (divisor == 1) {
            sizes.push_back({1, camera, measured_views.front().truth, preview_ms});
        } else if (budget.chooses_size && orbit.width >= kBudgetMinViewSide &&
                   orbit.height >= kBudgetMinViewSide) {
            CandidateSize size{divisor, Camera::orbit(orbit, plan.bounds), {}, 0.0};
            const auto start = Clock::now();
            size.rendering =
                renderer->render_ground_truth(size.camera, plan.transfer_function, truth_settings)
                    .rgba;
            size.preview_ms = 1e3 * seconds_since(start);
            sizes.push_back(std::move(size));
        }
    }
    // Smallest first: within an interval count the cheaper sizes are measured first.
    std::reverse(sizes.begin(), sizes.end());

    std::vector<std::pair<int, IntervalMode>> candidates;
    if (budget.chooses_intervals) {
        for (const int count : kBudgetIntervalCounts) {
            for (const IntervalMode mode :
                 {IntervalMode::uniform, IntervalMode::histogram_equalized,
                  IntervalMode::opacity_adaptive}) {
                candidates.emplace_back(count, mode);
            }
        }
    } else {
        candidates.emplace_back(config.interval_count, config.interval_mode);
    }
    // Half first, for every interval set; float only where that cannot meet the budget, for the
    // most accurate half candidate (float stores twice the bytes in the same time, and pays only
    // where half's rounding is what limits the accuracy: depths beyond its range, say).
    const StoragePrecision first_precision =
        budget.chooses_precision ? StoragePrecision::half : config.precision;
    const auto affordable = [&](const BudgetRecord& c) {
        return (!budget.bytes_per_step || c.bytes <= share * *budget.bytes_per_step) &&
               (!budget.ms_per_step || c.milliseconds <= share * *budget.ms_per_step);
    };
    const auto accurate = [&](const BudgetRecord& c) { return accurate_enough(budget, c.psnr_db); };
    // A candidate's proxies as compute_field makes them, and what its accuracy is measured with.
    struct CandidateProxies {
        int count = 0;
        IntervalMode mode = IntervalMode::uniform;
        const CandidateSize* size = nullptr;
        ViewRecord view;
        std::vector<double> scales;
        std::vector<float> colours;
        double pass_ms = 0.0;
    };
    // Encodes the candidate at `precision`, reads it back as a reader would, and measures the
    // held-out edit in every measured view: at the candidate's size (a turned view as the
    // Explorer turns the stored one, keeping its size), shown at the asked size.
    const auto measure = [&](const CandidateProxies& proxies, StoragePrecision precision) {
        BudgetRecord candidate;
        candidate.field = plan.name;
        candidate.intervals = proxies.count;
        candidate.interval_mode = proxies.mode;
        candidate.precision = precision;
        candidate.size_divisor = proxies.size->divisor;
        const Camera& source = proxies.size->camera;
        StepRecord record;
        record.field = plan.name;
        const archive_format::EncodedView encoded = archive_format::encode_view(
            record, proxies.view, precision, config.compression, "budget check");
        candidate.bytes = view_count * static_cast<double>(encoded.bytes.size());
        candidate.milliseconds = view_count * (proxies.pass_ms + proxies.size->preview_ms);
        const ProxyFrame stored = archive_format::decode_frame(
            std::vector<char>(encoded.bytes.begin(), encoded.bytes.end()), "budget check",
            encoded.parts, false);
        candidate.psnr_db = std::numeric_limits<double>::infinity();
        for (const BudgetView& target : measured_views) {
            const bool turned = &target != &measured_views.front();
            const double psnr_db = psnr_as_shown(
                target.truth,
                recolour(held_out_attenuation(stored, source, turned, target.azimuth_offset_deg,
                                              proxies.scales),
                         proxies.colours));
            candidate.views.push_back({target.azimuth_offset_deg, psnr_db});
            candidate.psnr_db = std::min(candidate.psnr_db, psnr_db);
        }
        return candidate;
    };
    const auto meets = [&](const BudgetRecord& c) { return affordable(c) && accurate(c); };
    std::vector<BudgetRecord> measured;
    std::optional<CandidateProxies> most_accurate;  // of the affordable ones measured so far
    double most_accurate_db = -std::numeric_limits<double>::infinity();
    for (const auto& [count, mode] : candidates) {
        // Bytes and time grow with the count: past a count that met an accuracy budget (both
        // modes measured), larger ones can only cost more. An easy budget costs two passes.
        if (budget.psnr_db && !measured.empty() && measured.back().intervals != count &&
            std::any_of(measured.begin(), measured.end(), meets)) {
            break;
        }
        // The single-perspective pass as compute_field makes it, with these intervals.
        ProxyRequest request;
        request.isovalues = plan.isovalues;
        request.intervals = renderer->choose_intervals(count, mode, &plan.transfer_function);
        request.transfer_function = plan.transfer_function;
        request.march.step_voxels = config.step_voxels;
        request.depth_layers = config.proxies.depth;
        request.interleaving = config.proxies.interleaving;
        request.entry_depth = config.proxies.entry_depth;
        for (const CandidateSize& size : sizes) {
            const auto start = Clock::now();
            ProxyFrame frame = renderer->render(size.camera, request);
            CandidateProxies proxies;
            proxies.count = count;
            proxies.mode = mode;
            proxies.size = &size;
            proxies.pass_ms = 1e3 * seconds_since(start);
            proxies.scales = opacity_scales(plan.transfer_function, held_out, *request.intervals);
            proxies.colours = interval_colours(held_out, *request.intervals);
            // Bytes as the writer stores the view (the rendering is the preview's size).
            if (config.proxies.rendering) frame.rendering = size.rendering;
            proxies.view.field = plan.name;
            proxies.view.view = view;
            proxies.view.view.orbit.width = size.camera.width();
            proxies.view.view.orbit.height = size.camera.height();
            proxies.view.transfer_function = plan.transfer_function;
            proxies.view.single = std::move(frame);
            measured.push_back(measure(proxies, first_precision));
            const BudgetRecord& candidate = measured.back();
            if (budget.chooses_precision && affordable(candidate) &&
                candidate.psnr_db > most_accurate_db) {
                most_accurate_db = candidate.psnr_db;
                most_accurate = std::move(proxies);
            }
        }
    }
    if (most_accurate && std::none_of(measured.begin(), measured.end(), meets)) {
        measured.push_back(measure(*most_accurate, StoragePrecision::single));
    }
    // With an accuracy asked: the cheapest (bytes, then time) that meets every limit. Else (or
    // without one: only cost limits) the cheapest of the affordable ones within
    // kBudgetPsnrTolerance of the most accurate; else the cheapest.
    const BudgetRecord* chosen = choose_candidate(
        measured, budget.psnr_db.has_value(), affordable, accurate,
        [](const BudgetRecord& a, const BudgetRecord& b) {
            return a.bytes < b.bytes || (a.bytes == b.bytes && a.milliseconds < b.milliseconds);
        });
    BudgetRecord choice = *chosen;
    choice.met = affordable(choice) && accurate(choice);
    if (config.light_field && budget.chooses_light_field) {
        choice.light_field = check_light_field_budget(plan, choice, measured_views);
    }
    if (fits_colour_model(plan.name) && budget.chooses_colour_model) {
        const auto size = std::find_if(sizes.begin(), sizes.end(), [&](const CandidateSize& c) {
            return c.divisor == choice.size_divisor;
        });
        INSITU_CHECK(size != sizes.end());
        choice.colour_model = check_colour_model_budget(plan, choice, size->camera, measured_views);
    }
    choice.check_milliseconds = 1e3 * seconds_since(check_start);
    return choice;
}

BudgetRecord::ColourModelChoice Instrument::Impl::check_colour_model_budget(
    const FieldPlan& plan, const BudgetRecord& views, const Camera& source,
    const std::vector<BudgetView>& targets) const {
    using Choice = BudgetRecord::ColourModelChoice;
    const BudgetConfig& budget = *config.budget;
    const double share = 1.0 / static_cast<double>(config.fields.size());
    // The fit's time comes on top of the views' passes; its K x L table's bytes are nothing.
    const auto affordable = [&](const Choice& c) {
        return !budget.ms_per_step ||
               views.milliseconds + c.milliseconds <= share * *budget.ms_per_step;
    };
    const auto accurate = [&](const Choice& c) { return accurate_enough(budget, c.psnr_db); };

    // The training pairs compute_field fits on (attenuation under each training function from
    // the chosen intervals, and its ground truth), in the stored view at the size chosen.
    ProxyRequest request;
    request.isovalues = plan.isovalues;
    request.intervals =
        renderer->choose_intervals(views.intervals, views.interval_mode, &plan.transfer_function);
    request.march.step_voxels = config.step_voxels;
    request.depth_layers = false;
    const RenderSettings truth_settings = budget_truth_settings();
    std::vector<Image> training_attenuation, training_colour;
    request.mean_depth = false;
    for (const TransferFunction& tf : config.training_transfer_functions) {
        request.transfer_function = tf;
        training_attenuation.push_back(renderer->render(source, request).attenuation);
        training_colour.push_back(renderer->render_ground_truth(source, tf, truth_settings).rgba);
    }
    // The held-out edit's attenuation in each measured view, as the Explorer estimates it (a
    // turned view synthesised from the stored one's proxies first).
    request.mean_depth = true;
    request.depth_layers = config.proxies.depth;  // as the view is stored
    request.transfer_function = plan.transfer_function;
    const ProxyFrame stored = renderer->render(source, request);
    const std::vector<double> scales = opacity_scales(
        plan.transfer_function, halved_opacity(plan.transfer_function), *request.intervals);
    std::vector<Image> edited;
    for (std::size_t v = 0; v < targets.size(); ++v) {  // the stored view first, as measured
        edited.push_back(
            held_out_attenuation(stored, source, v > 0, targets[v].azimuth_offset_deg, scales));
    }

    std::vector<Choice> measured;
    for (const int clusters : kBudgetColourModelClusters) {
        ColourModelSettings settings;
        settings.clusters = clusters;
        const auto start = Clock::now();
        const ColourModel model = ColourModel::fit(training_attenuation, training_colour, settings);
        Choice candidate;
        candidate.clusters = clusters;
        candidate.milliseconds = 1e3 * seconds_since(start);
        candidate.psnr_db = std::numeric_limits<double>::infinity();
        for (std::size_t v = 0; v < targets.size(); ++v) {
            candidate.psnr_db = std::min(candidate.psnr_db,
                                         psnr_as_shown(targets[v].truth, model.predict(edited[v])));
        }
        measured.push_back(candidate);
        // Fewest clusters first (the fit's time grows with K): the first that meets it is taken.
        if (budget.psnr_db && affordable(candidate) && accurate(candidate)) break;
        // Fewer distinct attenuation vectors than K: a larger K fits the same model.
        if (model.clusters() < clusters) break;
    }
    const Choice* chosen = choose_candidate(
        measured, budget.psnr_db.has_value(), affordable, accurate,
        [](const Choice& a, const Choice& b) { return a.milliseconds < b.milliseconds; });
    Choice choice = *chosen;
    choice.met = affordable(choice) && accurate(choice);
    return choice;
}

BudgetRecord::LightFieldChoice Instrument::Impl::check_light_field_budget(
    const FieldPlan& plan, const BudgetRecord& views,
    const std::vector<BudgetView>& targets) const {
    using Choice = BudgetRecord::LightFieldChoice;
    const BudgetConfig& budget = *config.budget;
    const LightFieldSettings& asked = *config.light_field;
    const double share = 1.0 / static_cast<double>(config.fields.size());
    // The views came first: the light field gets what they left.
    const auto affordable = [&](const Choice& c) {
        return (!budget.bytes_per_step ||
                views.bytes + c.bytes <= share * *budget.bytes_per_step) &&
               (!budget.ms_per_step ||
                views.milliseconds + c.milliseconds <= share * *budget.ms_per_step);
    };
    const auto accurate = [&](const Choice& c) { return accurate_enough(budget, c.psnr_db); };

    // What the light field shows is measured: an attenuation light field carries the held-out
    // edit (through its reconstructed a_j, as the Explorer edits), one without shows the run's
    // own function only, so that is its truth (one more ground-truth pass per view).
    LightFieldRequest request;
    request.settings = asked;
    request.transfer_function = plan.transfer_function;
    request.isovalues = plan.isovalues;
    request.march.step_voxels = config.step_voxels;
    const TransferFunction held_out = halved_opacity(plan.transfer_function);
    std::vector<double> scales;
    std::vector<float> colours;
    std::vector<Image> own_truths;
    if (asked.attenuation) {
        request.intervals = renderer->choose_intervals(views.intervals, views.interval_mode,
                                                       &plan.transfer_function);
        scales = opacity_scales(plan.transfer_function, held_out, *request.intervals);
        colours = interval_colours(held_out, *request.intervals);
    } else {
        for (const BudgetView& target : targets) {
            own_truths.push_back(renderer
                                     ->render_ground_truth(target.camera, plan.transfer_function,
                                                           budget_truth_settings())
                                     .rgba);
        }
    }
    const archive_format::LightFieldEncoding encoding =
        archive_format::light_field_encoding(config.precision, config.compression);

    // Cheapest first (cameras x pixels per map, what bytes and capture time grow with).
    std::vector<std::pair<int, int>> candidates;  // (cameras, size)
    for (const int cameras : kBudgetLightFieldCameraCounts) {
        for (const int divisor : kBudgetLightFieldSizeDivisors) {
            const int size = asked.size / divisor;
            if (divisor > 1 && size < kBudgetMinLightFieldSide) continue;
            candidates.emplace_back(cameras, size);
        }
    }
    std::stable_sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
        return double(a.first) * a.second * a.second < double(b.first) * b.second * b.second;
    });
    std::vector<Choice> measured;
    for (const auto& [cameras, size] : candidates) {
        const LightFieldRig rig = LightFieldRig::around(plan.bounds, cameras, size);
        // Only the cameras the measured views read: they reconstruct those views exactly as the
        // whole rig does.
        std::set<int> seen;
        for (const BudgetView& target : targets) {
            for (const int k : light_field_cameras_seen(rig, target.camera)) seen.insert(k);
        }
        // Orbit views frame the bounds (a perspective eye outside their sphere), so they read
        // some camera.
        INSITU_CHECK(!seen.empty());
        request.settings.cameras = cameras;
        request.settings.size = size;
        request.cameras.assign(seen.begin(), seen.end());
        const auto start = Clock::now();
        LightFieldRecord record{plan.name, capture_light_field(*renderer, rig, request)};
        const double whole_rig = static_cast<double>(cameras) / static_cast<double>(seen.size());
        Choice candidate;
        candidate.cameras = cameras;
        candidate.size = size;
        candidate.milliseconds = 1e3 * seconds_since(start) * whole_rig;
        StepRecord step;
        step.field = plan.name;
        candidate.bytes = static_cast<double>(archive_format::encode_light_field(
                                                  step, record, encoding, "budget check")
                                                  .bytes.size()) *
                          whole_rig;
        LightFieldReconstructionSettings settings;
        settings.attenuation = asked.attenuation;
        candidate.psnr_db = std::numeric_limits<double>::infinity();
        for (std::size_t v = 0; v < targets.size(); ++v) {
            const LightFieldReconstruction seen_view =
                reconstruct_light_field(record.light_field, targets[v].camera, settings);
            const Image shown =
                asked.attenuation
                    ? recolour(estimate_attenuation(seen_view.attenuation, seen_view.mean_depth,
                                                    nullptr, scales),
                               colours)
                    : seen_view.rgba;
            const Image& truth = asked.attenuation ? targets[v].truth : own_truths[v];
            candidate.psnr_db = std::min(candidate.psnr_db, psnr_rgb_db(truth, shown));
        }
        measured.push_back(candidate);
        // Cheapest first: the first that meets the budget is the one to take.
        if (budget.psnr_db && affordable(candidate) && accurate(candidate)) break;
    }
    // As for the views (measured cheapest first, so a candidate that met is the last one).
    const Choice* chosen =
        choose_candidate(measured, budget.psnr_db.has_value(), affordable, accurate,
                         [](const Choice& a, const Choice& b) { return a.bytes < b.bytes; });
    Choice choice = *chosen;
    choice.met = affordable(choice) && accurate(choice);
    return choice;
}

Instrument::Impl::FieldPlan Instrument::Impl::plan_distributed_field(
    const std::string& name, const std::vector<const Field*>& blocks, std::int64_t step,
    double& composite_seconds) {
    Communicator& ranks = *communicator;
    const int me = ranks.rank();
    LocalFailure failure;
    std::optional<Field> block;
    failure.guard([&] {
        if (blocks.size() == 1) block = *blocks.front();
        if (blocks.size() > 1) block = join_blocks(blocks, joined_blocks);
    });
    // Every rank learns every block's extent, and decomposes the grid the same way.
    const BlockExtent mine = block ? BlockExtent::of(*block) : BlockExtent{};
    auto start = Clock::now();
    const std::vector<Bytes> extents = agree(ranks, failure, doubles_bytes(mine.to_values()));
    composite_seconds += seconds_since(start);
    std::vector<BlockExtent> all;
    for (const Bytes& bytes : extents) {
        const std::vector<double> values = bytes_doubles(bytes);
        if (values.size() != BlockExtent::kValues) fail<Error>("block extent of a rank cut short");
        all.push_back(BlockExtent::from_values(values.data()));
    }
    const Decomposition grid = decompose(name, all);

    // This rank's part: the upload, and what it owns of the range and histogram.
    ValueRange local;
    local.min = std::numeric_limits<double>::infinity();
    local.max = -local.min;
    failure.guard([&] {
        if (!block) return;
        renderer->upload(grid.marched_block(*block, me));
        renderer->set_region(grid.region(me));
        const DeviceVolume& volume = renderer->volume();
        const ValueRange counts = grid.owned_counts(volume.host_values, volume.dims, me);
        local.finite_count = counts.finite_count;
        local.nonfinite_count = counts.nonfinite_count;
        // The marched ghost layer holds the neighbour's own values, so min and max over the
        // marched blocks are those of the grid.
        if (!volume.range.empty()) {
            local.min = volume.range.min;
            local.max = volume.range.max;
        }
    });
    start = Clock::now();
    agree(ranks, failure);
    std::vector<double> low{local.min};
    std::vector<double> high{local.max};
    std::vector<double> counts{static_cast<double>(local.finite_count),
                               static_cast<double>(local.nonfinite_count)};
    ranks.all_reduce(low, Reduction::min);
    ranks.all_reduce(high, Reduction::max);
    ranks.all_reduce(counts, Reduction::sum);
    composite_seconds += seconds_since(start);
    ValueRange range;
    range.finite_count = static_cast<std::int64_t>(counts[0]);
    range.nonfinite_count = static_cast<std::int64_t>(counts[1]);
    if (!range.empty()) {
        range.min = low[0];
        range.max = high[0];
    }
    check_range(name, range, step);

    FieldPlan plan;
    plan.name = name;
    plan.bounds = grid.bounds;
    plan.has_block = block.has_value();
    const double min = range.empty() ? 0.0 : range.min;
    const double max = range.empty() ? 0.0 : range.max;
    // The grid's histogram: the sum of the ranks' counts of the samples each owns, over the
    // agreed range (a rank without a block adds zeros, as every rank reduces).
    ValueHistogram histogram = ValueHistogram::of({}, min, max);
    failure.guard([&] {
        if (!block) return;
        const DeviceVolume& volume = renderer->volume();
        histogram =
            ValueHistogram::of(grid.owned_values(volume.host_values, volume.dims, me), min, max);
    });
    start = Clock::now();
    ranks.all_reduce(histogram.counts, Reduction::sum);
    agree(ranks, failure);
    composite_seconds += seconds_since(start);
    plan.summary.field = name;
    plan.summary.histogram = std::move(histogram);
    plan.summary.nonfinite_samples = range.nonfinite_count;
    plan.transfer_function = transfer_function_for(name, plan.summary.histogram);
    const std::optional<std::vector<double>>& layers = config.layers_of(name);
    plan.isovalues =
        layers ? *layers : opacity_peaks(plan.transfer_function, range, config.max_auto_layers);
    if (config.interval_mode == IntervalMode::uniform) {
        plan.intervals = IntervalSet::uniform(min, max, config.interval_count);
    } else {
        // The sum of the ranks' histograms of the samples each owns: the grid's histogram.
        const std::size_t bins = static_cast<std::size_t>(64 * config.interval_count);
        std::vector<double> histogram(bins, 0.0);
        failure.guard([&] {
            if (!block) return;
            const DeviceVolume& volume = renderer->volume();
            histogram = IntervalSet::equalization_histogram(
                grid.owned_values(volume.host_values, volume.dims, me), min, max,
                config.interval_count);
        });
        if (histogram.size() != bins) histogram.assign(bins, 0.0);  // as every rank reduces
        start = Clock::now();
        ranks.all_reduce(histogram, Reduction::sum);
        agree(ranks, failure);
        composite_seconds += seconds_since(start);
        plan.intervals =
            config.interval_mode == IntervalMode::opacity_adaptive
                ? IntervalSet::opacity_adaptive(histogram, min, max, config.interval_count,
                                                plan.transfer_function)
                : IntervalSet::from_equalization_histogram(histogram, min, max,
                                                           config.interval_count);
    }
    return plan;
}

void Instrument::Impl::compute_field(const FieldPlan& plan, StepRecord& record,
                                     double& composite_seconds) {
    const std::string& name = plan.name;
    const TransferFunction& transfer_function = plan.transfer_function;
    record.fields.push_back(plan.summary);
    if (plan.budget) record.budget.push_back(*plan.budget);
    const std::vector<double>& isovalues = plan.isovalues;
    const IntervalSet& intervals = plan.intervals;

    // The passes: on one process straight from the renderer; distributed, this rank's block's
    // partial pass (none without a block) composited at rank 0, which alone keeps the result.
    // A rank whose pass fails still takes part in every composite and says so afterwards.
    LocalFailure failure;
    const auto timed = [&](auto&& composite) {
        const auto start = Clock::now();
        auto result = composite();
        composite_seconds += seconds_since(start);
        return result;
    };
    const auto truth = [&](const Camera& camera, const TransferFunction& tf,
                           const RenderSettings& settings) -> Image {
        if (!communicator) return renderer->render_ground_truth(camera, tf, settings).rgba;
        std::optional<Rendering> partial;
        if (plan.has_block) {
            failure.guard([&] { partial = renderer->render_ground_truth(camera, tf, settings); });
        }
        // Every rank takes part in every composite, failed or not (see LocalFailure).
        Rendering composited;
        failure.always([&] {
            composited = timed([&] {
                return composite_rendering(*communicator, camera.width(), camera.height(),
                                           partial ? &*partial : nullptr, 0);
            });
        });
        return composited.rgba;
    };
    // A view's single-perspective pass (tilt 0) or its volume distortion camera's.
    const auto proxies = [&](const OrbitView& orbit, double tilt_deg, bool multi_perspective,
                             const ProxyRequest& request) -> ProxyFrame {
        const Camera camera = Camera::orbit(orbit, plan.bounds);
        const DistortionCamera distortion = DistortionCamera::orbit(orbit, plan.bounds, tilt_deg);
        if (!communicator) {
            return multi_perspective ? renderer->render(distortion, request)
                                     : renderer->render(camera, request);
        }
        ProxyRequest march = request;
        march.training_transfer_functions.clear();
        // A block cannot count re-entries of intervals the ray met in front of it (see
        // ProxyRequest::interleaving): distributed archives carry no interleaving, and the
        // Explorer's edit trust then goes without that term.
        march.interleaving = false;
        // Likewise the entry depth: the first interval a block sees may not be the ray's.
        march.entry_depth = false;
        std::optional<ProxyFrame> partial;
        if (plan.has_block) {
            failure.guard([&] {
                partial = multi_perspective ? renderer->render(distortion, march)
                                            : renderer->render(camera, march);
            });
        }
        ProxyFrame frame;
        failure.always([&] {
            frame = timed([&] {
                const ProxyFrame shell = multi_perspective
                                             ? frame_shell(distortion.base(), tilt_deg, true, march)
                                             : frame_shell(camera, 0.0, false, march);
                return composite_proxies(*communicator, shell, partial ? &*partial : nullptr, 0);
            });
        });
        for (const TransferFunction& tf : request.training_transfer_functions) {
            frame.training.push_back(truth(camera, tf, request.march));
        }
        return frame;
    };

    ProxyRequest base;
    base.isovalues = isovalues;
    base.intervals = intervals;
    base.transfer_function = transfer_function;
    base.march.step_voxels = config.step_voxels;

    ProxyRequest single = base;
    single.depth_layers = config.proxies.depth;
    single.attenuation = config.proxies.attenuation;
    single.mean_depth = config.proxies.attenuation;
    single.optical_depth = config.proxies.optical_depth;
    single.interleaving = config.proxies.attenuation && config.proxies.interleaving;
    single.entry_depth = config.proxies.attenuation && config.proxies.entry_depth;
    // The colour model maps the stored attenuation to colour, so it is fitted only where that
    // attenuation is stored. Training renderings are rendered when the model or the archive
    // needs them, and stored only on request ("keep_training_images").
    // Training functions are in the top-level function's units: only its fields train.
    const bool trains = config.trains(name) && !config.training_transfer_functions.empty();
    const bool fits_model = fits_colour_model(name);
    if (trains && (config.keep_training_images || fits_model)) {
        single.training_transfer_functions = config.training_transfer_functions;
    }
    const bool wants_single = single.depth_layers || single.attenuation || single.optical_depth ||
                              !single.training_transfer_functions.empty();
    // Attenuation under each training function, from the same intervals, step and camera as
    // its training rendering: the pairs seed 000 §6.2 learns from.
    ProxyRequest training_attenuation = base;
    training_attenuation.depth_layers = false;
    training_attenuation.mean_depth = false;
    ColourModelSettings model_settings;
    model_settings.clusters = plan.budget && plan.budget->colour_model
                                  ? plan.budget->colour_model->clusters
                                  : config.colour_model.clusters;

    ProxyRequest multi = base;
    multi.depth_layers = config.proxies.distortion;
    multi.attenuation = config.proxies.multi_attenuation;
    multi.mean_depth = config.proxies.multi_attenuation;
    multi.optical_depth = config.proxies.multi_attenuation && config.proxies.optical_depth;
    const bool wants_multi = config.proxies.distortion || config.proxies.multi_attenuation;

    // The preview is what Cinema viewers show: the ground truth, unshaded like the proxies'
    // emission-absorption model, at the proxies' step. It marches on to T = 0 like the proxies:
    // it is also the stored view's "rendering", which the Explorer returns as that view exactly
    // (stopping at 0.99 left up to 1 % of the colour behind), and distributed, a block cannot
    // stop at an opacity it does not know is reached in front of it.
    RenderSettings preview_settings;
    preview_settings.step_voxels = config.step_voxels;
    preview_settings.early_termination_opacity = 1.0;

    // A budget that chooses the size stores every view of the field at its divided size.
    const int size_divisor =
        plan.budget && config.budget->chooses_size ? plan.budget->size_divisor : 1;
    for (ViewConfig view : config.views_of(name)) {
        view.orbit.width = std::max(1, view.orbit.width / size_divisor);
        view.orbit.height = std::max(1, view.orbit.height / size_divisor);
        ViewRecord out;
        out.view_index = static_cast<int>(record.views.size());
        out.field = name;
        out.view = view;
        out.transfer_function = transfer_function;
        out.training_transfer_functions = single.training_transfer_functions;
        if (plan.budget && config.budget->chooses_precision) out.precision = plan.budget->precision;
        const Camera camera = Camera::orbit(view.orbit, plan.bounds);
        if (wants_single) out.single = proxies(view.orbit, 0.0, false, single);
        if (fits_model) {
            std::vector<Image> attenuations;
            for (const TransferFunction& tf : config.training_transfer_functions) {
                training_attenuation.transfer_function = tf;
                attenuations.push_back(
                    proxies(view.orbit, 0.0, false, training_attenuation).attenuation);
            }
            // Only the writing rank holds the composited images.
            if (writes()) {
                failure.guard([&] {
                    out.single->colour_model =
                        ColourModel::fit(attenuations, out.single->training, model_settings);
                });
            }
            if (!config.keep_training_images) out.single->training.clear();
        }
        if (wants_multi) out.multi = proxies(view.orbit, view.distortion_tilt_deg, true, multi);
        out.preview = truth(camera, transfer_function, preview_settings);
        if (config.proxies.rendering) {
            if (!out.single) out.single = frame_shell(camera, 0.0, false, single);
            out.single->rendering = out.preview;
        }
        record.views.push_back(std::move(out));
    }
    if (communicator) {
        const auto start = Clock::now();
        agree(*communicator, failure);
        composite_seconds += seconds_since(start);
    } else if (failure.failed()) {
        fail_as(failure.kind, failure.message);
    }

    // The light field (seed 001) takes the proxies' samples, layers and intervals, so its
    // segments and attenuation mean what the views' proxies mean.
    if (config.light_field) {
        // Refused with a communicator at construction: segments have no exact composite.
        INSITU_CHECK(!communicator);
        LightFieldRequest request;
        request.settings = *config.light_field;
        if (plan.budget && plan.budget->light_field) {
            request.settings.cameras = plan.budget->light_field->cameras;
            request.settings.size = plan.budget->light_field->size;
        }
        request.transfer_function = transfer_function;
        request.isovalues = isovalues;
        if (request.settings.attenuation) request.intervals = intervals;
        request.march.step_voxels = config.step_voxels;
        const LightFieldRig rig =
            LightFieldRig::around(plan.bounds, request.settings.cameras, request.settings.size);
        record.light_fields.push_back({name, capture_light_field(*renderer, rig, request)});
    }
}

Status Instrument::Impl::enqueue(StepRecord record, double compute_seconds) {
    std::unique_lock<std::mutex> lock(mutex);
    ++statistics.steps_executed;
    statistics.compute_seconds += compute_seconds;
    // The record being written counts too: writer_queue bounds the steps held in memory.
    const auto full = [&] {
        return queue.size() + static_cast<std::size_t>(writing) >=
               static_cast<std::size_t>(config.writer_queue);
    };
    if (full()) {
        if (config.when_full == WhenFull::drop) {
            ++statistics.steps_dropped;
            return Status::dropped;
        }
        const auto start = Clock::now();
        room.wait(lock, [&] { return !full(); });
        statistics.blocked_seconds += seconds_since(start);
    }
    queue.push_back(std::move(record));
    work_ready.notify_one();
    return Status::ok;
}

void Instrument::Impl::writer_loop() {
    // Encoding and writing only when the simulation's core has nothing else to do (see
    // writer_thread.hpp); refused, the writer keeps the simulation's priority and loses nothing.
    archive_format::lower_writer_thread_priority();
    for (;;) {
        std::int64_t step = 0;
        std::uint64_t bytes = 0;
        std::string failure;
        std::exception_ptr failure_exception;
        double seconds = 0.0;
        {
            std::unique_lock<std::mutex> lock(mutex);
            work_ready.wait(lock, [&] { return stopping || !queue.empty(); });
            if (queue.empty()) return;  // stopping, and everything queued is written
            StepRecord record = std::move(queue.front());
            queue.pop_front();
            ++writing;
            lock.unlock();

            step = record.step;
            const auto start = Clock::now();
            try {
                bytes = archive->write(record).bytes();
            } catch (const std::exception& error) {
                failure = error.what();
                failure_exception = std::current_exception();
            } catch (...) {
                failure = "unknown exception";
                failure_exception = std::current_exception();
            }
            seconds = seconds_since(start);
        }  // the record's images are freed here, before the queue reports room

        {
            std::lock_guard<std::mutex> lock(mutex);
            --writing;
            statistics.write_seconds += seconds;
            if (failure.empty()) {
                ++statistics.steps_written;
                statistics.bytes_written += bytes;
            } else {
                // Counted and made the status together: a distributed run tells every rank of
                // write_failures at the next step, and must find it once the error is counted.
                record_error_locked("writing step " + std::to_string(step) + ": " + failure,
                                    classify(failure_exception), /*from_writer=*/true);
                write_failure = failure_exception;
                ++write_failures;
            }
        }
        // After the unlock: the waiting simulation wakes and preempts this low-priority thread
        // at once, and must not then find the mutex still held by it.
        room.notify_all();
    }
}

Status Instrument::Impl::finalize() {
    if (finalized) return Status::ok;
    finalized = true;
    {
        std::lock_guard<std::mutex> lock(mutex);
        stopping = true;
    }
    work_ready.notify_all();
    if (writer.joinable()) writer.join();

    std::exception_ptr failure;
    {
        std::lock_guard<std::mutex> lock(mutex);
        failure = write_failure;
        std::ostringstream summary;
        summary << "finalized \"" << config.archive << "\": " << statistics;
        // The cost a user can see and bound (issue 18): the share of the run's wall time the
        // simulation spent waiting in execute(), beside its own time between the calls.
        const double wall = statistics.execute_seconds + statistics.simulation_seconds;
        if (wall > 0.0) {
            summary << std::fixed << std::setprecision(3) << "; in situ "
                    << statistics.execute_seconds << " s inside execute, " << std::setprecision(1)
                    << 100.0 * statistics.execute_seconds / wall << " % of " << std::setprecision(3)
                    << wall << " s wall since the first call (simulation "
                    << statistics.simulation_seconds << " s between calls; writer "
                    << statistics.write_seconds << " s on its own thread)";
        }
        if (config.budget) summary << "; " << budget_summary();
        if (!first_error.empty()) summary << "; first error: " << first_error;
        if (!last_error.empty() && last_error != first_error) {
            summary << "; last error: " << last_error;
        }
        log(summary.str());
    }
    if (communicator) {
        // Every rank returns what rank 0's writer met.
        Bytes verdict{static_cast<std::uint8_t>(failure ? 1 : 0)};
        if (failure) {
            std::lock_guard<std::mutex> lock(mutex);
            append_bytes(verdict, last_error.data(), last_error.size());
        }
        communicator->broadcast(verdict, 0);
        if (verdict.at(0) == 0) return Status::ok;
        if (!writes()) {
            const std::string message =
                "rank 0: writing the archive failed: " +
                std::string(reinterpret_cast<const char*>(verdict.data()) + 1, verdict.size() - 1);
            record_error(message, ErrorKind::io, /*from_writer=*/true);
            if (options.rethrow_errors) fail<IoError>(message);
            return Status::error;
        }
    }
    if (!failure) return Status::ok;
    if (options.rethrow_errors) std::rethrow_exception(failure);
    return Status::error;
}

Instrument::Instrument(InstrumentConfig config, InstrumentOptions options)
    : impl_(std::make_unique<Impl>()) {
    Impl& impl = *impl_;
    impl.options = options;
    impl.communicator = options.communicator;
    if (impl.communicator) {
        impl.open_distributed(std::move(config));
        return;
    }
    config.validate();
    impl.config = std::move(config);
    // The compute device first: without one nothing is written, not even an empty archive.
    impl.renderer = std::make_unique<ProxyRenderer>();
    impl.open_archive();
    impl.writer = std::thread(&Impl::writer_loop, &impl);
}

std::unique_ptr<Instrument> Instrument::from_json_file(const std::string& path,
                                                       InstrumentOptions options) {
    std::vector<std::string> unknown;
    InstrumentConfig config = InstrumentConfig::from_json_file(path, &unknown);
    const std::string warning = refuse_unknown_keys(config, unknown, path + ": ");
    auto instrument = std::make_unique<Instrument>(std::move(config), options);
    instrument->impl_->adopt_unknown_keys(std::move(unknown), warning);
    return instrument;
}

std::unique_ptr<Instrument> Instrument::from_json_text(const std::string& text,
                                                       InstrumentOptions options) {
    std::vector<std::string> unknown;
    InstrumentConfig config = InstrumentConfig::from_json_text(text, &unknown);
    const std::string warning = refuse_unknown_keys(config, unknown, "configuration: ");
    auto instrument = std::make_unique<Instrument>(std::move(config), options);
    instrument->impl_->adopt_unknown_keys(std::move(unknown), warning);
    return instrument;
}

Instrument::~Instrument() {
    try {
        finalize();
    } catch (...) {
        // Only rethrow_errors lets finalize() throw; a destructor must not.
    }
}

Status Instrument::execute(std::int64_t step, double time, const std::vector<Field>& fields) {
    // Times the call, whatever it returns, and the simulation's own time since the last one.
    struct CallTimer {
        Impl& impl;
        Clock::time_point start = Clock::now();
        ~CallTimer() {
            const Clock::time_point end = Clock::now();
            std::lock_guard<std::mutex> lock(impl.mutex);
            impl.statistics.execute_seconds += std::chrono::duration<double>(end - start).count();
            if (impl.last_return) {
                impl.statistics.simulation_seconds +=
                    std::chrono::duration<double>(start - *impl.last_return).count();
            }
            impl.last_return = end;
        }
    } timer{*impl_};
    try {
        return impl_->execute(step, time, fields);
    } catch (const std::exception& error) {
        impl_->record_error(error.what(), classify(std::current_exception()),
                            /*from_writer=*/false);
        if (impl_->options.rethrow_errors) throw;
    } catch (...) {
        impl_->record_error("step " + std::to_string(step) + ": unknown exception",
                            ErrorKind::unknown, /*from_writer=*/false);
        if (impl_->options.rethrow_errors) throw;
    }
    return Status::error;
}

Status Instrument::finalize() {
    try {
        return impl_->finalize();
    } catch (...) {
        // Only a rethrown write failure (rethrow_errors) or a failed join get here; the write
        // failure is already counted.
        if (impl_->options.rethrow_errors) throw;
    }
    return Status::error;
}

bool Instrument::selects(std::int64_t step) const {
    return impl_->selects(step);
}

void Instrument::report_error(const std::string& message, ErrorKind kind) {
    impl_->record_error(message, kind, /*from_writer=*/false);
}

InstrumentStatistics Instrument::statistics() const {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    return impl_->statistics;
}

std::string Instrument::last_error() const {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    return impl_->last_error;
}

std::string Instrument::first_error() const {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    return impl_->first_error;
}

ErrorKind Instrument::last_error_kind() const {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    return impl_->last_error_kind;
}

const InstrumentConfig& Instrument::config() const {
    return impl_->config;
}

const std::vector<std::string>& Instrument::unknown_keys() const {
    return impl_->unknown_keys;
}

}  // namespace insitu
