// insitu-capture: the offline path. Reads a time series of files already on disk (.vti, .pvd,
// .vdb or raw) and writes the same timestep proxy archive an Instrument writes in situ, from the
// same JSON configuration.
//
// Steps are numbered first-step + position in the input list (a .pvd contributes its data sets in
// timestep order); a step's time is the .pvd timestep, or its step number.
//
// Exit status: 0 success (inputs skipped with --on-error skip are named on stderr); 2 bad
// arguments or bad input (unknown flag, malformed value, unreadable configuration, an input that
// cannot be read when --on-error is stop, or no input readable at all); 1 anything else (no
// OpenCL device, an archive that cannot be written). Every failure is one line on stderr naming
// the flag, value or file; the archive keeps every step written before it.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "arguments.hpp"
#include "cli.hpp"
#include "insitu/capture_input.hpp"
#include "insitu/config.hpp"
#include "insitu/error.hpp"
#include "insitu/instrument.hpp"
#include "insitu/raw_reader.hpp"

namespace {

constexpr const char* kProgram = "insitu-capture";
using insitu::one_line;
using insitu::cli::parse_finite;
using insitu::cli::parse_integer;
using insitu::cli::split_exactly;
using insitu::cli::UsageError;

/// A failure that is not the user's input (exit 1).
class RuntimeFailure : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

enum class OnError { stop, skip };

struct Arguments {
    std::string config_path;
    std::string out_path;
    std::optional<insitu::Index3> raw_dims;
    std::optional<insitu::capture::RawType> raw_type;
    glm::dvec3 raw_spacing{1.0};
    bool raw_big_endian = false;
    std::string field;
    OnError on_error = OnError::stop;
    std::int64_t first_step = 0;
    std::vector<std::string> inputs;
};

// ---------------------------------------------------------------------------------------------
// Value parsers (arguments.hpp: each takes the whole token or fails).

insitu::Index3 parse_dims(const std::string& flag, const std::string& text) {
    const auto parts = split_exactly(flag, text, ',', 3, "NX,NY,NZ");
    return {parse_integer<std::int64_t>(flag, parts[0], 1),
            parse_integer<std::int64_t>(flag, parts[1], 1),
            parse_integer<std::int64_t>(flag, parts[2], 1)};
}

glm::dvec3 parse_spacing(const std::string& flag, const std::string& text) {
    const auto parts = split_exactly(flag, text, ',', 3, "SX,SY,SZ");
    glm::dvec3 spacing{parse_finite(flag, parts[0]), parse_finite(flag, parts[1]),
                       parse_finite(flag, parts[2])};
    for (int axis = 0; axis < 3; ++axis) {
        if (!(spacing[axis] > 0.0))
            throw UsageError(flag + ": spacing must be positive, got \"" + text + "\"");
    }
    return spacing;
}

// ---------------------------------------------------------------------------------------------
// The option table: one row per flag; help and parsing both come from it.

using Option = insitu::cli::TableOption<Arguments>;

const std::vector<Option>& options() {
    using V = const std::string&;
    static const std::vector<Option> table = {
        {"--config", "CONFIG.json", true,
         "libinsitu JSON configuration (views, fields, transfer function, proxies)", "",
         [](Arguments& a, V, V v) { a.config_path = v; }},
        {"--out", "ARCHIVE", true,
         "archive directory (overrides the configuration's \"archive\"; an existing archive is "
         "continued)",
         "", [](Arguments& a, V, V v) { a.out_path = v; }},
        {"--field", "NAME", false, "array (.vti) or grid (.vdb) to read",
         "the configuration's first field; neither given: the file's only array or grid",
         [](Arguments& a, V, V v) { a.field = v; }},
        {"--raw-dims", "NX,NY,NZ", false, "samples per axis of raw inputs", "",
         [](Arguments& a, V f, V v) { a.raw_dims = parse_dims(f, v); }},
        {"--raw-type", "TYPE", false,
         "raw sample type: uint8 int8 uint16 int16 uint32 int32 uint64 int64 float32 float64", "",
         [](Arguments& a, V f, V v) {
             try {
                 a.raw_type = insitu::capture::parse_raw_type(v);
             } catch (const insitu::Error& error) {
                 throw UsageError(f + ": " + error.what());
             }
         }},
        {"--raw-spacing", "SX,SY,SZ", false, "raw sample spacing in world units", "1,1,1",
         [](Arguments& a, V f, V v) { a.raw_spacing = parse_spacing(f, v); }},
        {"--raw-big-endian", nullptr, false, "raw inputs are big-endian", "little-endian",
         [](Arguments& a, V, V) { a.raw_big_endian = true; }},
        {"--on-error", "stop|skip", false,
         "an input that cannot be read stops the capture or is skipped", "stop",
         [](Arguments& a, V f, V v) {
             if (v != "stop" && v != "skip") {
                 throw UsageError(f + ": expected stop or skip, got \"" + v + "\"");
             }
             a.on_error = v == "stop" ? OnError::stop : OnError::skip;
         }},
        {"--first-step", "N", false, "step number of the first input", "0",
         [](Arguments& a, V f, V v) { a.first_step = parse_integer<std::int64_t>(f, v, 0); }},
    };
    return table;
}

const insitu::cli::CommandHelp& command_help() {
    static const insitu::cli::CommandHelp help = [] {
        insitu::cli::CommandHelp h;
        h.usage = std::string(kProgram) + " --config CONFIG.json --out ARCHIVE [options] INPUT...";
        h.description =
            "Writes a timestep proxy archive from files on disk, one timestep per input, with the\n"
            "configuration an Instrument uses in situ. The input type follows from the name:\n"
            "  .vti  VTK image data (point or cell array; cell values sit at cell centres)\n"
            "  .pvd  VTK collection of .vti files (time from each data set's timestep)\n"
            "  .vdb  OpenVDB float/double grid (active bounding box densified; level sets get a\n"
            "        layer at the zero crossing unless the configuration names its layers)\n"
            "  other raw samples, x fastest, described by --raw-dims and --raw-type\n"
            "After \"--\" every argument is an INPUT.";
        h.options = insitu::cli::help_rows(options());
        h.notes =
            "A progress bar (steps, rate, ETA) is drawn on stderr when it is a terminal.\n"
            "Exit status: 0 success, 2 bad arguments or input, 1 other failures.";
        return h;
    }();
    return help;
}

Arguments parse_arguments(int argc, char** argv) {
    Arguments arguments;
    insitu::cli::parse_table(argc, argv, options(), arguments, &arguments.inputs);
    if (arguments.inputs.empty()) throw UsageError("no INPUT files given (see --help)");
    if (arguments.raw_dims.has_value() != arguments.raw_type.has_value()) {
        throw UsageError(arguments.raw_dims ? "--raw-dims needs --raw-type"
                                            : "--raw-type needs --raw-dims");
    }
    return arguments;
}

// ---------------------------------------------------------------------------------------------

std::string format_duration(double seconds) {
    const auto total = static_cast<std::int64_t>(std::llround(std::max(0.0, seconds)));
    std::ostringstream text;
    text << total / 60 << ":" << std::setw(2) << std::setfill('0') << total % 60;
    return text.str();
}

/// Steps done, rate and ETA on one redrawn line of stderr, only when stderr is a terminal.
class ProgressBar {
public:
    explicit ProgressBar(std::size_t total)
        : total_(total), enabled_(isatty(STDERR_FILENO) == 1), start_(Clock::now()) {}

    void update(std::size_t done) {
        if (!enabled_) return;
        const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
        const double rate = elapsed > 0.0 ? static_cast<double>(done) / elapsed : 0.0;
        constexpr std::size_t kWidth = 30;
        const std::size_t filled = total_ == 0 ? kWidth : done * kWidth / total_;
        std::ostringstream line;
        line << "\r[" << std::string(filled, '#') << std::string(kWidth - filled, ' ') << "] "
             << done << "/" << total_ << " steps  " << std::fixed << std::setprecision(2) << rate
             << " steps/s  ETA "
             << (done > 0 && rate > 0.0 ? format_duration(static_cast<double>(total_ - done) / rate)
                                        : std::string("--:--"))
             << "\x1b[K";
        std::cerr << line.str() << std::flush;
        drawn_ = true;
    }
    /// Prints a line of its own (a warning) without tearing the bar.
    void message(const std::string& text) {
        if (drawn_) std::cerr << "\r\x1b[K";
        std::cerr << text << "\n";
    }
    void finish() {
        if (drawn_) std::cerr << "\n";
        drawn_ = false;
    }

private:
    using Clock = std::chrono::steady_clock;
    std::size_t total_;
    bool enabled_;
    bool drawn_ = false;
    Clock::time_point start_;
};

// Whether the configuration file names any of `keys` (it has parsed already: it is JSON).
bool configuration_sets(const std::string& path, std::initializer_list<const char*> keys) {
    std::ifstream in(path);
    const nlohmann::json json = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!json.is_object()) return false;
    return std::any_of(keys.begin(), keys.end(),
                       [&](const char* key) { return json.contains(key); });
}

/// The configuration as --config and --out give it, its unknown keys refused or warned about
/// as an Instrument does. Everything cheap is checked before any input is read and OpenCL is
/// started.
insitu::InstrumentConfig capture_configuration(const Arguments& arguments) {
    std::vector<std::string> unknown_keys;
    insitu::InstrumentConfig config =
        insitu::InstrumentConfig::from_json_file(arguments.config_path, &unknown_keys);
    config.archive = arguments.out_path;
    // As an Instrument does: a typo is an error unless the configuration says "strict": false.
    try {
        const std::string warning =
            insitu::refuse_unknown_keys(config, unknown_keys, arguments.config_path + ": ");
        if (!warning.empty()) std::cerr << kProgram << ": warning: " << warning << "\n";
    } catch (const insitu::ParseError& error) {
        throw UsageError(error.what());
    }
    // Each input is a step the user chose to capture: the simulation's default cadence (every
    // 10th step) applies only when the configuration asks for a cadence itself.
    if (!configuration_sets(arguments.config_path, {"every", "steps"})) config.every = 1;
    return config;
}

/// How the readers read each input: the array or grid, the field's name, raw samples' layout.
insitu::capture::InputOptions input_options_of(const Arguments& arguments,
                                               const insitu::InstrumentConfig& config,
                                               bool field_from_file) {
    insitu::capture::InputOptions input_options;
    input_options.field_name = config.fields.front();
    input_options.array_name = arguments.field.empty() ? config.fields.front() : arguments.field;
    if (field_from_file) input_options.field_name = input_options.array_name = "";
    if (arguments.raw_dims) {
        insitu::capture::RawOptions raw;
        raw.dims = *arguments.raw_dims;
        raw.type = *arguments.raw_type;
        raw.spacing_world = arguments.raw_spacing;
        raw.big_endian = arguments.raw_big_endian;
        input_options.raw = raw;
    }
    return input_options;
}

/// The steps the inputs hold, in order (a .pvd contributes each of its data sets); an input this
/// build cannot read, or raw input without its layout, is refused before anything is read.
std::vector<insitu::capture::InputStep> input_steps(
    const std::vector<std::string>& inputs, const insitu::capture::InputOptions& input_options) {
    namespace capture = insitu::capture;
    std::vector<capture::InputStep> steps;
    for (const std::string& path : inputs) {
        const capture::InputKind kind = capture::input_kind(path);
        if (!capture::supported(kind)) {
            throw UsageError("\"" + path + "\": " + capture::to_string(kind) +
                             " input is not supported by this build (built without " +
                             (kind == capture::InputKind::vdb ? "OpenVDB" : "VTK") + ")");
        }
        if (kind == capture::InputKind::raw && !input_options.raw) {
            throw UsageError("\"" + path +
                             "\" is not .vti, .pvd or .vdb, so it is read as raw, which needs "
                             "--raw-dims and --raw-type");
        }
        if (kind == capture::InputKind::pvd) {
            const std::vector<capture::InputStep> expanded = capture::expand_pvd(path);
            steps.insert(steps.end(), expanded.begin(), expanded.end());
        } else {
            steps.push_back({path, kind, std::nullopt});
        }
    }
    return steps;
}

/// One capture of the input steps into the archive: the Instrument, started at the first input
/// read, and the count of what became of each step, for the summary line.
class Capture {
public:
    Capture(const Arguments& arguments, insitu::InstrumentConfig config,
            insitu::capture::InputOptions input_options, bool field_from_file,
            std::size_t step_count)
        : arguments_(arguments),
          config_(std::move(config)),
          input_options_(std::move(input_options)),
          field_from_file_(field_from_file),
          step_count_(step_count),
          progress_(step_count) {}

    /// Loads and executes each step in turn; an input that cannot be used is skipped or ends the
    /// capture, as --on-error says.
    void capture(const std::vector<insitu::capture::InputStep>& steps) {
        progress_.update(0);
        for (std::size_t i = 0; i < steps.size(); ++i) {
            const insitu::capture::InputStep& input = steps[i];
            const std::int64_t step = arguments_.first_step + static_cast<std::int64_t>(i);
            std::unique_ptr<insitu::capture::LoadedStep> loaded;
            try {
                loaded = insitu::capture::load_step(input, input_options_);
            } catch (const insitu::Error& error) {
                input_failed(error.what());
                progress_.update(i + 1);
                continue;
            }
            if (!instrument_) start_instrument(*loaded, input.path);
            const double time = input.time.value_or(static_cast<double>(step));
            count(instrument_->execute(step, time, {loaded->field()}), input.path, step);
            progress_.update(i + 1);
        }
        progress_.finish();
    }

    /// Finalizes the archive and prints the summary line.
    void finish() {
        if (!instrument_) {
            throw UsageError("none of the " + std::to_string(step_count_) +
                             " inputs could be read; nothing was captured");
        }
        if (instrument_->finalize() == insitu::Status::error) {
            throw RuntimeFailure("writing the archive \"" + config_.archive +
                                 "\" failed: " + instrument_->last_error());
        }
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        const insitu::InstrumentStatistics statistics = instrument_->statistics();
        std::ostringstream summary;
        summary << std::fixed << std::setprecision(2) << kProgram << ": "
                << statistics.steps_written << " of " << step_count_ << " steps archived ("
                << skipped_ << " skipped, " << not_selected_ << " not selected by the cadence, "
                << dropped_ << " dropped) in " << seconds << " s, "
                << (seconds > 0.0 ? captured_ / seconds : 0.0) << " steps/s" << field_note_
                << layers_note_ << " -> " << config_.archive;
        std::cout << summary.str() << "\n";
    }

private:
    /// The Instrument, from the configuration completed by the first input read: the field's
    /// name where the file names it, a level set's zero crossing as its layer.
    void start_instrument(const insitu::capture::LoadedStep& loaded, const std::string& path) {
        if (field_from_file_) {
            const std::string name = loaded.field().name();
            if (name.empty()) {
                throw UsageError("\"" + path +
                                 "\": its array has no name, which an archive's field needs");
            }
            config_.fields = {name};
            input_options_.array_name = input_options_.field_name = name;
            field_note_ = ", field \"" + name + "\" (named by the first file)";
        }
        // Level sets: the zero crossing is a layer unless the configuration names layers.
        if (!config_.layers && !loaded.default_isovalues().empty()) {
            config_.layers = loaded.default_isovalues();
            layers_note_ = ", layers at the level set's zero crossing";
        }
        insitu::InstrumentOptions instrument_options;
        instrument_options.log = false;  // this tool reports, one line per problem
        try {
            instrument_ = std::make_unique<insitu::Instrument>(config_, instrument_options);
        } catch (const insitu::Error& error) {
            progress_.finish();
            throw RuntimeFailure(std::string("cannot start capturing into \"") + config_.archive +
                                 "\": " + error.what());
        }
    }

    /// Counts what became of a step; a step the Instrument refuses is an input that cannot be
    /// used, any other error ends the capture.
    void count(insitu::Status status, const std::string& path, std::int64_t step) {
        if (status == insitu::Status::error) {
            const std::string why = "\"" + path + "\" (step " + std::to_string(step) +
                                    "): " + instrument_->last_error();
            if (instrument_->last_error_kind() == insitu::ErrorKind::invalid_argument) {
                input_failed(why);
            } else {
                progress_.finish();
                instrument_->finalize();
                throw RuntimeFailure(one_line(why) + " (the archive keeps the " +
                                     std::to_string(captured_) + " steps before it)");
            }
        } else if (status == insitu::Status::ok) {
            ++captured_;
        } else if (status == insitu::Status::not_selected) {
            ++not_selected_;
        } else {
            ++dropped_;
        }
    }

    /// An input that cannot be used: skipped, or the end of the run (the archive keeps what the
    /// Instrument already wrote: finalize drains its queue).
    void input_failed(const std::string& why) {
        if (arguments_.on_error == OnError::skip) {
            ++skipped_;
            // Every reader's message names the file already.
            progress_.message(std::string(kProgram) + ": skipped: " + one_line(why));
            return;
        }
        progress_.finish();
        if (instrument_) instrument_->finalize();
        throw UsageError(one_line(why) + " (stopped; the archive keeps the " +
                         std::to_string(captured_) +
                         " step(s) captured before; --on-error skip goes on)");
    }

    const Arguments& arguments_;
    insitu::InstrumentConfig config_;
    insitu::capture::InputOptions input_options_;
    bool field_from_file_;
    std::size_t step_count_;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
    ProgressBar progress_;
    std::unique_ptr<insitu::Instrument> instrument_;
    std::size_t captured_ = 0;
    std::size_t not_selected_ = 0;
    std::size_t dropped_ = 0;
    std::size_t skipped_ = 0;
    std::string layers_note_;
    std::string field_note_;
};

int run(const Arguments& arguments) {
    insitu::InstrumentConfig config = capture_configuration(arguments);
    // Neither --field nor "fields": the first file's only array or grid (its active scalars or
    // first scalar grid where there are several), under its own name, which every later file
    // must then hold too.
    const bool field_from_file =
        arguments.field.empty() && !configuration_sets(arguments.config_path, {"fields"});
    insitu::capture::InputOptions input_options =
        input_options_of(arguments, config, field_from_file);
    const std::vector<insitu::capture::InputStep> steps =
        input_steps(arguments.inputs, input_options);
    Capture capture(arguments, std::move(config), std::move(input_options), field_from_file,
                    steps.size());
    capture.capture(steps);
    capture.finish();
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    // A RuntimeFailure is not the user's input: exit 1, like every non-input error.
    return insitu::cli::run_command(kProgram, insitu::cli::program_arguments(argc, argv),
                                    command_help(),
                                    [&] { return run(parse_arguments(argc, argv)); });
}
