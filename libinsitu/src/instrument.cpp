#include "insitu/instrument.hpp"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "archive/writer_thread.hpp"
#include "insitu/archive/archive.hpp"
#include "insitu/core/camera.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/colour_model.hpp"
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

    // Touched by the writer thread only (after construction).
    std::unique_ptr<ArchiveWriter> archive;

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
        if (options.log) std::cerr << "insitu: " << one_line(line) << std::endl;
    }

    /// Counts an error of execute() or of the writer; each source logs its first error only, so a
    /// failure that repeats every step does not flood the simulation's stderr.
    void record_error(const std::string& message, ErrorKind kind, bool from_writer) {
        std::lock_guard<std::mutex> lock(mutex);
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
    StepRecord compute(std::int64_t step, double time, const std::vector<Field>& fields);
    /// Renders the views of one configured field into `record`, numbering them from
    /// record.views.size().
    void compute_field(const Field& field, StepRecord& record);
    Status enqueue(StepRecord record, double compute_seconds);
    void writer_loop();
    Status finalize();
};

Status Instrument::Impl::execute(std::int64_t step, double time, const std::vector<Field>& fields) {
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
        return Status::not_selected;
    }
    if (!config.selects(step)) {
        last_step = step;
        return Status::not_selected;
    }
    for (const std::string& name : config.fields) {
        const bool present = std::any_of(fields.begin(), fields.end(),
                                         [&](const Field& f) { return f.name() == name; });
        if (!present) {
            fail<InvalidArgument>("step ", step, ": field \"", name, "\" missing (got ",
                                  joined_names(fields), ")");
        }
    }

    const auto start = Clock::now();
    StepRecord record = compute(step, time, fields);
    const double compute_seconds = seconds_since(start);
    // From here the step number is used, even if the queue drops the step.
    last_step = step;
    return enqueue(std::move(record), compute_seconds);
}

StepRecord Instrument::Impl::compute(std::int64_t step, double time,
                                     const std::vector<Field>& fields) {
    StepRecord record;
    record.step = step;
    record.time = time;
    record.field = config.fields.front();
    for (const std::string& name : config.fields) {
        std::vector<const Field*> blocks;
        for (const Field& field : fields) {
            if (field.name() == name) blocks.push_back(&field);
        }
        // One block is marched where it lies (zero-copy up to the upload); tiles are joined.
        if (blocks.size() == 1) {
            compute_field(*blocks.front(), record);
        } else {
            compute_field(join_blocks(blocks, joined_blocks), record);
        }
    }
    return record;
}

void Instrument::Impl::compute_field(const Field& field, StepRecord& record) {
    const std::int64_t step = record.step;
    // The one read of the simulation's memory: the upload packs the interior into the renderer's
    // host staging vector and the device buffer; everything below reads those copies.
    renderer->upload(field);
    const DeviceVolume& volume = renderer->volume();
    // The renderers sample float32: a finite double beyond its range becomes Inf there, and the
    // intervals and layers chosen from the range would describe values no sample holds.
    const double float_max = std::numeric_limits<float>::max();
    if (volume.range.min < -float_max || volume.range.max > float_max) {
        fail<InvalidArgument>("step ", step, ": field \"", field.name(), "\" has values in [",
                              volume.range.min, ", ", volume.range.max,
                              "], beyond the float32 range +-", float_max,
                              " the renderers sample in");
    }
    if (volume.range.nonfinite_count > 0) {
        {
            std::lock_guard<std::mutex> lock(mutex);
            statistics.nonfinite_samples += volume.range.nonfinite_count;
        }
        if (!nonfinite_reported) {
            nonfinite_reported = true;
            log("warning: step " + std::to_string(step) + ": field \"" + field.name() + "\" has " +
                std::to_string(volume.range.nonfinite_count) +
                " NaN/Inf samples, treated as empty space (counted in statistics, reported "
                "once)");
        }
    }

    // Layers and intervals come from this step's data: "model no more than a scene needs".
    const TransferFunction& transfer_function = config.transfer_function_of(field.name());
    const std::optional<std::vector<double>>& layers = config.layers_of(field.name());
    const std::vector<double> isovalues =
        layers ? *layers : renderer->choose_layers(transfer_function, config.max_auto_layers);
    const IntervalSet intervals =
        renderer->choose_intervals(config.interval_count, config.interval_mode);

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
    // The colour model maps the stored attenuation to colour, so it is fitted only where that
    // attenuation is stored. Training renderings are rendered when the model or the archive
    // needs them, and stored only on request ("keep_training_images").
    // Training functions are in the top-level function's units: only its fields train.
    const bool trains = config.trains(field.name()) && !config.training_transfer_functions.empty();
    const bool fits_model = trains && config.colour_model.enabled && config.proxies.attenuation;
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
    model_settings.clusters = config.colour_model.clusters;

    ProxyRequest multi = base;
    multi.depth_layers = config.proxies.distortion;
    multi.attenuation = config.proxies.multi_attenuation;
    multi.mean_depth = config.proxies.multi_attenuation;
    multi.optical_depth = config.proxies.multi_attenuation && config.proxies.optical_depth;
    const bool wants_multi = config.proxies.distortion || config.proxies.multi_attenuation;

    // The preview is what Cinema viewers show: the ground truth, unshaded like the proxies'
    // emission-absorption model, at the proxies' step.
    RenderSettings preview_settings;
    preview_settings.step_voxels = config.step_voxels;

    for (const ViewConfig& view : config.views_of(field.name())) {
        ViewRecord out;
        out.view_index = static_cast<int>(record.views.size());
        out.field = field.name();
        out.view = view;
        out.transfer_function = transfer_function;
        out.training_transfer_functions = single.training_transfer_functions;
        const Camera camera = Camera::orbit(view.orbit, volume.bounds);
        if (wants_single) out.single = renderer->render(camera, single);
        if (fits_model) {
            std::vector<Image> attenuations;
            for (const TransferFunction& tf : config.training_transfer_functions) {
                training_attenuation.transfer_function = tf;
                attenuations.push_back(renderer->render(camera, training_attenuation).attenuation);
            }
            out.single->colour_model =
                ColourModel::fit(attenuations, out.single->training, model_settings);
            if (!config.keep_training_images) out.single->training.clear();
        }
        if (wants_multi) {
            out.multi = renderer->render(
                DistortionCamera::orbit(view.orbit, volume.bounds, view.distortion_tilt_deg),
                multi);
        }
        out.preview =
            renderer->render_ground_truth(camera, transfer_function, preview_settings).rgba;
        record.views.push_back(std::move(out));
    }

    // The light field (seed 001) takes the proxies' samples, layers and intervals, so its
    // segments and attenuation mean what the views' proxies mean.
    if (config.light_field) {
        LightFieldRequest request;
        request.settings = *config.light_field;
        request.transfer_function = transfer_function;
        request.isovalues = isovalues;
        if (request.settings.attenuation) request.intervals = intervals;
        request.march.step_voxels = config.step_voxels;
        const LightFieldRig rig =
            LightFieldRig::around(volume.bounds, request.settings.cameras, request.settings.size);
        record.light_fields.push_back({field.name(), capture_light_field(*renderer, rig, request)});
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

        if (!failure.empty())
            record_error("writing step " + std::to_string(step) + ": " + failure,
                         classify(failure_exception), /*from_writer=*/true);
        {
            std::lock_guard<std::mutex> lock(mutex);
            --writing;
            statistics.write_seconds += seconds;
            if (failure.empty()) {
                ++statistics.steps_written;
                statistics.bytes_written += bytes;
            } else {
                write_failure = failure_exception;
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
        if (!first_error.empty()) summary << "; first error: " << first_error;
        if (!last_error.empty() && last_error != first_error) {
            summary << "; last error: " << last_error;
        }
        log(summary.str());
    }
    if (!failure) return Status::ok;
    if (options.rethrow_errors) std::rethrow_exception(failure);
    return Status::error;
}

Instrument::Instrument(InstrumentConfig config, InstrumentOptions options)
    : impl_(std::make_unique<Impl>()) {
    Impl& impl = *impl_;
    config.validate();
    impl.config = std::move(config);
    impl.options = options;
    // The compute device first: without one nothing is written, not even an empty archive.
    impl.renderer = std::make_unique<ProxyRenderer>();

    const std::string& path = impl.config.archive;
    std::error_code ignored;
    const bool continuing = fs::exists(fs::path(path) / "manifest.json", ignored);
    try {
        impl.archive = std::make_unique<ArchiveWriter>(impl.config);
    } catch (const fs::filesystem_error& error) {
        fail<IoError>("cannot open archive \"", path, "\": ", error.what());
    }
    if (continuing) {
        // execute() rejects these up front, so a replayed step fails at once and synchronously
        // instead of later on the writer thread.
        const ArchiveReader existing(path);
        for (std::int64_t step : existing.steps()) impl.archived_steps.insert(step);
    }
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
