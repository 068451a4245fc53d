#include "insitu/instrument.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <set>

#include "archive/archive_format.hpp"
#include "archive/asynchronous_writer.hpp"
#include "budget/field_budget_check.hpp"
#include "core/elapsed.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/budget/budget_controller.hpp"
#include "insitu/error.hpp"
#include "insitu/render/proxy_renderer.hpp"
#include "parallel/agreement.hpp"
#include "parallel/composited_passes.hpp"
#include "parallel/distributed_budget.hpp"
#include "parallel/reduced_field_statistics.hpp"
#include "representation/representation.hpp"
#include "run_statistics.hpp"
#include "step/field_plan.hpp"
#include "step/local_field_statistics.hpp"
#include "step/step_passes.hpp"
#include "step/step_recipe.hpp"

namespace insitu {

namespace {

namespace fs = std::filesystem;

// Largest step number the manifest holds exactly (see Impl::check_step).
constexpr std::int64_t kMaxStep = (std::int64_t{1} << 53) - 1;

std::string joined_names(const std::vector<Field>& fields) {
    std::string names;
    for (const Field& field : fields) names += (names.empty() ? "" : ", ") + field.name();
    return names.empty() ? "none" : names;
}

}  // namespace

// The orchestrator: it wires the rooms (the field's statistics and plan in step/, the budget's
// choice in budget/, each representation's capture in representation/, the writer in archive/,
// the agreement of a distributed run in parallel/) and holds the run's lifecycle.
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
    std::optional<std::int64_t> halo_step;  ///< the step the halo check ran at ("first")
    // Replayed steps noted (by execute() or, in a rerun that asks first, by selects()): each
    // counted once, one notice for the run.
    bool replay_reported = false;
    std::set<std::int64_t> replayed_steps;
    std::vector<float> joined_blocks;  ///< storage of a field joined from several blocks
    /// When the last execute() returned: the simulation's own time runs from there.
    std::optional<SteadyClock::time_point> last_return;
    /// With a "budget": its choice per field (the same on every rank of a distributed run).
    std::optional<BudgetController> budget;
    /// Rank 0's renderer of the whole field a distributed budget check gathers.
    std::unique_ptr<ProxyRenderer> whole_field_renderer;

    /// The ranks of a distributed run (InstrumentOptions::communicator), or null.
    std::shared_ptr<Communicator> communicator;
    /// Whether this process writes (and logs): rank 0, or the only process.
    bool writes() const { return !communicator || communicator->rank() == 0; }

    /// Shared with the writer thread (which it outlives).
    RunStatistics run{[this](const std::string& line) { log(line); }};
    /// The archive's writer: this process's when it writes, else null.
    std::unique_ptr<AsynchronousWriter> writer;

    void log(const std::string& line) const {
        // In a distributed run every rank meets the same warnings: rank 0 says them once.
        if (options.log && writes()) std::cerr << "insitu: " << one_line(line) << std::endl;
    }

    /// Keeps the configuration's unknown keys ("strict": false) and logs refuse_unknown_keys's
    /// warning about them.
    void adopt_unknown_keys(std::vector<std::string> keys, const std::string& warning) {
        unknown_keys = std::move(keys);
        if (!warning.empty()) log("warning: " + warning);
    }

    /// Instrument::selects, const for the caller, notes a replayed step here.
    bool selects(std::int64_t step) {
        if (finalized || (last_step && step <= *last_step) || !config.selects(step)) return false;
        if (archived_steps.count(step) == 0) return true;
        note_replay(step);
        return false;
    }

    /// A restarted simulation replays steps an earlier run already archived: those are kept as
    /// they are ("on_existing": "append") and skipped, counted and noticed once, whether the
    /// simulation asks selects() first (then it never calls execute() for them) or not.
    void note_replay(std::int64_t step) {
        if (!replayed_steps.insert(step).second) return;
        run.update([](InstrumentStatistics& s) { ++s.steps_replayed; });
        if (replay_reported) return;
        replay_reported = true;
        log("notice: step " + std::to_string(step) + " is already in archive \"" + config.archive +
            "\" (a restarted run replaying it): archived steps are skipped, counted in "
            "statistics (\"on_existing\": \"replace\" starts the archive anew)");
    }

    /// The constructor's work on one process: the compute device first (without one nothing is
    /// written, not even an empty archive), then the archive and its writer.
    void open(InstrumentConfig checked_config);
    /// The constructor's work with a communicator: every rank validates and makes its device,
    /// rank 0 opens the archive, and all agree (one failure fails every rank) and learn the
    /// archived steps.
    void open_distributed(InstrumentConfig distributed_config);
    /// Where the compressed field may be kept: every rank must reach the archive (each places its
    /// own blocks). Asked for, a rank that cannot is an error on every rank; by default the
    /// field is then not kept.
    void agree_on_volume_folder();
    /// Opens (or continues) the archive, notes the steps it holds and starts its writer.
    void open_archive();
    Status execute(std::int64_t step, double time, const std::vector<Field>& fields);
    Status execute_distributed(std::int64_t step, double time, const std::vector<Field>& fields);
    /// Every rank's step and time, agreed (the same on every rank, else InvalidArgument).
    void agree_on_step(std::int64_t step, double time, double& composite_seconds);
    /// The checks of execute() that need no field (step, time, order, finalize).
    void check_step(std::int64_t step, double time) const;
    /// Whether a checked step is skipped (already archived, counted and noticed once; or not
    /// selected by the cadence); notes it as the last step then.
    bool skips(std::int64_t step);
    /// The step's record: every configured field planned and captured (on rank 0, composited;
    /// elsewhere the record is not kept). Adds the time spent agreeing and compositing.
    StepRecord compute(std::int64_t step, double time, const std::vector<Field>& fields,
                       double& composite_seconds);
    /// Uploads field `name` (its one block, its tiles joined, or this rank's block) and returns
    /// the statistics its plan is chosen from: this process's, or reduced over the ranks.
    std::unique_ptr<FieldStatistics> upload(std::int64_t step, const std::string& name,
                                            const std::vector<const Field*>& blocks,
                                            double& composite_seconds);
    /// Checks the value range and reports NaN/Inf samples (once per run).
    void check_range(const std::string& name, const ValueRange& range, std::int64_t step);
    /// The budget's choice for the plan's field at this step (checking when one is due; a
    /// distributed check's gather and wait in `composite_seconds`), applied to its intervals.
    void apply_budget(FieldPlan& plan, FieldStatistics& statistics, double& composite_seconds);
    /// Captures every representation of one planned field into `record`, by its recipe.
    void capture(const FieldPlan& plan, StepRecord& record, double& composite_seconds);
    /// Hands the record to the writer: ok, or dropped where the queue is full.
    Status queue(StepRecord record, double compute_seconds);
    Status finalize();
    /// Every rank returns what rank 0's writer met.
    Status finalize_distributed(const std::exception_ptr& failure);
};

void Instrument::Impl::open(InstrumentConfig checked_config) {
    config = std::move(checked_config);
    if (config.budget) budget.emplace(*config.budget, config.fields.size());
    renderer = std::make_unique<ProxyRenderer>();
    open_archive();
}

void Instrument::Impl::open_archive() {
    const std::string& path = config.archive;
    std::error_code ignored;
    const bool continuing = fs::exists(fs::path(path) / "manifest.json", ignored);
    std::unique_ptr<ArchiveWriter> archive;
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
    writer = std::make_unique<AsynchronousWriter>(std::move(archive), config.writer_queue,
                                                  config.when_full, run);
}

void Instrument::Impl::open_distributed(InstrumentConfig distributed_config) {
    LocalFailure failure;
    failure.guard([&] { distributed_config.validate(); });
    config = std::move(distributed_config);
    if (config.budget) budget.emplace(*config.budget, config.fields.size());
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
    if (!config.no_volume) agree_on_volume_folder();
}

void Instrument::Impl::agree_on_volume_folder() {
    const fs::path folder = fs::path(config.archive) / archive_format::kVolumeFolder;
    const std::string unreached = ranks_that_cannot_reach(*communicator, folder);
    if (unreached.empty()) return;
    const std::string why = "rank(s) " + unreached + " cannot reach the archive's folder \"" +
                            folder.string() +
                            "\", and each rank writes its own blocks of the compressed field";
    if (config.volume) {
        fail<InvalidArgument>("\"volume\": ", why,
                              "; put the archive on a file system every rank shares, or leave "
                              "\"volume\" out");
    }
    config.no_volume = true;
    log("note: " + why + ": the field is not kept (\"volume\": false)");
}

void Instrument::Impl::agree_on_step(std::int64_t step, double time, double& composite_seconds) {
    LocalFailure failure;
    failure.guard([&] { check_step(step, time); });
    // Rank 0 tells the others of writes that failed since the last step: the run's status is
    // the same on every rank.
    if (writes() && !failure.failed()) {
        if (const std::optional<std::string> error = run.untold_write_failure()) {
            failure.message =
                "an earlier step could not be written (" + *error + "); this step was not computed";
            failure.kind = ErrorKind::io;
        }
    }
    const auto start = SteadyClock::now();
    const std::vector<Bytes> said =
        agree(*communicator, failure, doubles_bytes({static_cast<double>(step), time}));
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
}

Status Instrument::Impl::execute_distributed(std::int64_t step, double time,
                                             const std::vector<Field>& fields) {
    double composite_seconds = 0.0;
    agree_on_step(step, time, composite_seconds);
    // The same on every rank: the archived steps and the cadence are.
    if (skips(step)) return Status::not_selected;

    const auto compute_start = SteadyClock::now();
    StepRecord record = compute(step, time, fields, composite_seconds);
    const double compute_seconds = seconds_since(compute_start);
    last_step = step;
    run.update([&](InstrumentStatistics& s) { s.composite_seconds += composite_seconds; });
    Status status = Status::ok;
    LocalFailure failure_to_queue;
    failure_to_queue.guard([&] {
        if (writes()) {
            status = queue(std::move(record), compute_seconds);
        } else {
            run.update([&](InstrumentStatistics& s) {
                ++s.steps_executed;
                s.compute_seconds += compute_seconds;
            });
        }
    });
    // Every rank returns rank 0's status (a step dropped there is dropped for all), told in
    // the agreement on the queueing's failure: one collective.
    const std::vector<Bytes> said =
        agree(*communicator, failure_to_queue, Bytes{static_cast<std::uint8_t>(status)});
    return static_cast<Status>(said.at(0).at(0));
}

bool Instrument::Impl::skips(std::int64_t step) {
    if (archived_steps.count(step) != 0) {
        last_step = step;
        note_replay(step);
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

    const auto start = SteadyClock::now();
    double composite_seconds = 0.0;  // none without a communicator
    StepRecord record = compute(step, time, fields, composite_seconds);
    const double compute_seconds = seconds_since(start);
    // From here the step number is used, even if the queue drops the step.
    last_step = step;
    return queue(std::move(record), compute_seconds);
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
        const std::unique_ptr<FieldStatistics> statistics =
            upload(step, name, blocks, composite_seconds);
        check_range(name, statistics->range(), step);
        FieldPlan plan = plan_field(config, name, *statistics);
        if (budget) apply_budget(plan, *statistics, composite_seconds);
        capture(plan, record, composite_seconds);
    }
    return record;
}

std::unique_ptr<FieldStatistics> Instrument::Impl::upload(std::int64_t step,
                                                          const std::string& name,
                                                          const std::vector<const Field*>& blocks,
                                                          double& composite_seconds) {
    // A rank may own nothing of a field: it passes no block, and marches nothing.
    if (communicator) {
        auto reduced = std::make_unique<ReducedFieldStatistics>(
            *communicator, *renderer, name, blocks, joined_blocks, composite_seconds);
        // "halo_check": every field of the first step computed (halo_step), or of every step.
        if (config.halo_check == HaloCheck::every ||
            (config.halo_check == HaloCheck::first && halo_step.value_or(step) == step)) {
            halo_step = step;
            for (const std::string& line : reduced->check_halos(step)) log("warning: " + line);
        }
        return reduced;
    }
    // One block is marched where it lies (zero-copy up to the upload); tiles are joined.
    if (blocks.size() == 1) return std::make_unique<LocalFieldStatistics>(*renderer, *blocks[0]);
    return std::make_unique<LocalFieldStatistics>(*renderer, join_blocks(blocks, joined_blocks));
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
        run.update([&](InstrumentStatistics& s) { s.nonfinite_samples += range.nonfinite_count; });
        if (!nonfinite_reported) {
            nonfinite_reported = true;
            log("warning: step " + std::to_string(step) + ": field \"" + name + "\" has " +
                std::to_string(range.nonfinite_count) +
                " NaN/Inf samples, treated as empty space (counted in statistics, reported "
                "once)");
        }
    }
}

void Instrument::Impl::apply_budget(FieldPlan& plan, FieldStatistics& statistics,
                                    double& composite_seconds) {
    // Fed the reduced histogram, every rank's controller makes the same checks; upload() made a
    // distributed field's statistics reduced over the ranks.
    plan.budget = budget->choice_for(plan.name, plan.summary.histogram, [&] {
        if (!communicator) return check_field_budget(config, *renderer, statistics, plan);
        return check_distributed_field_budget(*communicator, config,
                                              static_cast<ReducedFieldStatistics&>(statistics),
                                              plan, whole_field_renderer, composite_seconds);
    });
    if (config.budget->chooses_intervals) {
        plan.intervals = statistics.intervals(plan.budget->intervals, plan.budget->interval_mode,
                                              plan.transfer_function);
    }
}

void Instrument::Impl::capture(const FieldPlan& plan, StepRecord& record,
                               double& composite_seconds) {
    record.fields.push_back(plan.summary);
    if (plan.budget) record.budget.push_back(*plan.budget);
    const FieldRecipe recipe = field_recipe(config, plan);
    std::unique_ptr<StepPasses> passes;
    if (communicator) {
        passes = std::make_unique<CompositedPasses>(*communicator, *renderer, plan.has_block,
                                                    composite_seconds, representations().size(),
                                                    config.compositing, config.compositing_radix);
    } else {
        passes = std::make_unique<LocalPasses>(*renderer);
    }
    for (const auto& representation : representations()) {
        representation->capture(config, plan, recipe, *passes, record);
        passes->finish();
    }
}

Status Instrument::Impl::queue(StepRecord record, double compute_seconds) {
    return writer->enqueue(std::move(record), compute_seconds) ? Status::ok : Status::dropped;
}

Status Instrument::Impl::finalize() {
    if (finalized) return Status::ok;
    finalized = true;
    if (writer) writer->stop();
    const std::exception_ptr failure = run.write_failure();
    log(run.summary(config.archive, budget ? budget->summary() : std::string()));
    if (communicator) return finalize_distributed(failure);
    if (!failure) return Status::ok;
    if (options.rethrow_errors) std::rethrow_exception(failure);
    return Status::error;
}

Status Instrument::Impl::finalize_distributed(const std::exception_ptr& failure) {
    Bytes verdict{static_cast<std::uint8_t>(failure ? 1 : 0)};
    if (failure) {
        const std::string error = run.last_error();
        verdict.insert(verdict.end(), error.begin(), error.end());
    }
    communicator->broadcast(verdict, 0);
    if (verdict.at(0) == 0) return Status::ok;
    if (!writes()) {
        const std::string message =
            "rank 0: writing the archive failed: " +
            std::string(reinterpret_cast<const char*>(verdict.data()) + 1, verdict.size() - 1);
        run.record_error(message, ErrorKind::io, /*from_writer=*/true);
        if (options.rethrow_errors) fail<IoError>(message);
        return Status::error;
    }
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
    impl.open(std::move(config));
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
        SteadyClock::time_point start = SteadyClock::now();
        ~CallTimer() {
            const SteadyClock::time_point end = SteadyClock::now();
            const std::optional<SteadyClock::time_point> last_return = impl.last_return;
            impl.run.update([&](InstrumentStatistics& s) {
                s.execute_seconds += std::chrono::duration<double>(end - start).count();
                if (last_return) {
                    s.simulation_seconds +=
                        std::chrono::duration<double>(start - *last_return).count();
                }
            });
            impl.last_return = end;
        }
    } timer{*impl_};
    try {
        return impl_->execute(step, time, fields);
    } catch (const std::exception& error) {
        impl_->run.record_error(error.what(), classify(std::current_exception()),
                                /*from_writer=*/false);
        if (impl_->options.rethrow_errors) throw;
    } catch (...) {
        impl_->run.record_error("step " + std::to_string(step) + ": unknown exception",
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
    impl_->run.record_error(message, kind, /*from_writer=*/false);
}

InstrumentStatistics Instrument::statistics() const {
    return impl_->run.snapshot();
}

std::string Instrument::last_error() const {
    return impl_->run.last_error();
}

std::string Instrument::first_error() const {
    return impl_->run.first_error();
}

ErrorKind Instrument::last_error_kind() const {
    return impl_->run.last_error_kind();
}

const InstrumentConfig& Instrument::config() const {
    return impl_->config;
}

const std::vector<std::string>& Instrument::unknown_keys() const {
    return impl_->unknown_keys;
}

}  // namespace insitu
