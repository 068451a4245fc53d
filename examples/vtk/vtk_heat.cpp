// vtk-heat: a small VTK-based simulation coupled to libinsitu through the VTK adaptor.
//
// The simulation keeps its state where VTK codes do: a vtkImageData whose point array
// "temperature" (vtkFloatArray) it updates in place, with one layer of ghost points around the
// interior (fixed boundary values, marked in VTK's ghost array). Each step it solves
// explicit heat diffusion, dT/dt = kappa laplacian(T) + a heat source circling the box, and hands
// the image to an insitu::Instrument through insitu::vtk::to_field: no copy (the Field views the
// vtkFloatArray's memory) and the ghost layer skipped (from the ghost array).
//
// With --write-vti DIR it also writes every archived step as DIR/heat_NNNNNN.vti plus a
// DIR/heat.pvd collection, which insitu-capture turns into the same archive offline:
//   insitu-capture --config CONFIG.json --out offline.cdb --field temperature DIR/heat.pvd
//
// usage: vtk-heat ARCHIVE [--size N] [--steps S] [--every K] [--config CONFIG.json]
//                         [--write-vti DIR]
// Exit status: 0 done, 2 bad arguments or configuration, 1 a runtime failure; one line on stderr.
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLImageDataWriter.h>

#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "cli.hpp"
#include "insitu/config.hpp"
#include "insitu/error.hpp"
#include "insitu/instrument.hpp"
#include "insitu/vtk_adaptor.hpp"

namespace {

constexpr const char* kSynopsis =
    "vtk-heat ARCHIVE [--size N] [--steps S] [--every K] [--config CONFIG.json] "
    "[--write-vti DIR]";

using insitu::cli::UsageError;

struct Options {
    std::string archive;
    int size = 32;  ///< interior points per axis
    int steps = 40;
    int every = 10;
    std::string config_path;
    std::string vti_folder;
};

/// --help, its defaults those of Options.
const insitu::cli::CommandHelp& command_help() {
    static const insitu::cli::CommandHelp help = [] {
        const Options defaults;
        return insitu::cli::CommandHelp{
            kSynopsis,
            "Simulates heat diffusion in a vtkImageData (a source circling the box) and archives "
            "its \"temperature\" array through libinsitu's VTK adaptor into ARCHIVE, without a "
            "copy.",
            {{"--size", "N", "interior points per axis, >= 4", std::to_string(defaults.size)},
             {"--steps", "S", "steps to simulate, >= 1", std::to_string(defaults.steps)},
             {"--every", "K", "archive every K steps (overrides the configuration's cadence)",
              std::to_string(defaults.every)},
             {"--config", "CONFIG.json", "libinsitu JSON configuration",
              "field temperature, one view, a ramp over the temperatures reached"},
             {"--write-vti", "DIR",
              "also write every archived step as DIR/heat_NNNNNN.vti and DIR/heat.pvd, for "
              "insitu-capture",
              "none"}},
            "Exit status: 0 done, 2 bad arguments or configuration, 1 a runtime failure; one line "
            "on stderr."};
    }();
    return help;
}

Options parse(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string token = argv[i];
        if (token.rfind("--", 0) != 0) {
            if (!options.archive.empty()) throw UsageError("unexpected argument " + token);
            options.archive = token;
            continue;
        }
        if (i + 1 >= argc) throw UsageError(token + " needs a value");
        const std::string value = argv[++i];
        if (token == "--size") {
            options.size = insitu::cli::parse_integer<int>(token, value, 4);
        } else if (token == "--steps") {
            options.steps = insitu::cli::parse_integer<int>(token, value, 1);
        } else if (token == "--every") {
            options.every = insitu::cli::parse_integer<int>(token, value, 1);
        } else if (token == "--config") {
            options.config_path = value;
        } else if (token == "--write-vti") {
            options.vti_folder = value;
        } else {
            throw UsageError("unknown option " + token);
        }
    }
    if (options.archive.empty()) throw UsageError(std::string("usage: ") + kSynopsis);
    return options;
}

/// The simulation: state in a vtkImageData, one ghost layer of fixed boundary points.
class HeatSimulation {
public:
    explicit HeatSimulation(int interior) : n_(interior + 2) {
        image_->SetDimensions(n_, n_, n_);
        const double spacing = 1.0 / interior;
        image_->SetSpacing(spacing, spacing, spacing);
        image_->SetOrigin(-spacing, -spacing, -spacing);  // interior point 0 at world 0
        temperature_->SetName("temperature");
        temperature_->SetNumberOfTuples(static_cast<vtkIdType>(n_) * n_ * n_);
        temperature_->Fill(0.0);
        ghosts_->SetName(vtkDataSetAttributes::GhostArrayName());
        ghosts_->SetNumberOfTuples(temperature_->GetNumberOfTuples());
        for (int k = 0; k < n_; ++k) {
            for (int j = 0; j < n_; ++j) {
                for (int i = 0; i < n_; ++i) {
                    const bool boundary =
                        i == 0 || j == 0 || k == 0 || i == n_ - 1 || j == n_ - 1 || k == n_ - 1;
                    ghosts_->SetValue(index(i, j, k),
                                      boundary ? vtkDataSetAttributes::DUPLICATEPOINT : 0);
                }
            }
        }
        image_->GetPointData()->AddArray(temperature_);
        image_->GetPointData()->AddArray(ghosts_);
        next_.resize(static_cast<std::size_t>(temperature_->GetNumberOfTuples()));
    }

    vtkImageData& image() { return *image_; }

    /// One explicit Euler step of dT/dt = kappa lap(T) + source, in place in the VTK array.
    void step(int step_number) {
        constexpr double kKappaDt = 0.12;  // kappa dt / h^2 <= 1/6 keeps explicit Euler stable
        const double angle = 0.15 * step_number;
        const double cx = 0.5 + 0.25 * std::cos(angle);
        const double cy = 0.5 + 0.25 * std::sin(angle);
        float* t = temperature_->GetPointer(0);
        const int interior = n_ - 2;
        for (int k = 1; k < n_ - 1; ++k) {
            for (int j = 1; j < n_ - 1; ++j) {
                for (int i = 1; i < n_ - 1; ++i) {
                    const vtkIdType c = index(i, j, k);
                    const double laplacian = t[index(i - 1, j, k)] + t[index(i + 1, j, k)] +
                                             t[index(i, j - 1, k)] + t[index(i, j + 1, k)] +
                                             t[index(i, j, k - 1)] + t[index(i, j, k + 1)] -
                                             6.0 * t[c];
                    const double x = (i - 1.0) / interior - cx;
                    const double y = (j - 1.0) / interior - cy;
                    const double z = (k - 1.0) / interior - 0.5;
                    const double source = 0.05 * std::exp(-(x * x + y * y + z * z) / 0.005);
                    next_[static_cast<std::size_t>(c)] =
                        static_cast<float>(t[c] + kKappaDt * laplacian + source);
                }
            }
        }
        for (int k = 1; k < n_ - 1; ++k) {
            for (int j = 1; j < n_ - 1; ++j) {
                for (int i = 1; i < n_ - 1; ++i) {
                    t[index(i, j, k)] = next_[static_cast<std::size_t>(index(i, j, k))];
                }
            }
        }
        temperature_->Modified();
    }

private:
    vtkIdType index(int i, int j, int k) const {
        return (static_cast<vtkIdType>(k) * n_ + j) * n_ + i;
    }

    int n_;
    vtkNew<vtkImageData> image_;
    vtkNew<vtkFloatArray> temperature_;
    vtkNew<vtkUnsignedCharArray> ghosts_;
    std::vector<float> next_;
};

/// Default configuration: field "temperature", one view, a ramp over the temperatures reached.
insitu::InstrumentConfig default_config() {
    return insitu::InstrumentConfig::from_json_text(R"({
        "fields": ["temperature"],
        "views": [{"azimuth": 30, "elevation": 25, "size": [128, 128]}],
        "transfer_function": {"points": [[0.0, 0, 0, 1, 0], [0.02, 0, 0, 1, 0],
                                         [0.3, 1, 0.5, 0, 1.0]], "unit_length": 0.05},
        "intervals": {"count": 8}})");
}

void write_vti(const std::string& folder, int step, vtkImageData& image, std::ofstream& pvd) {
    std::ostringstream name;
    name << "heat_" << std::setw(6) << std::setfill('0') << step << ".vti";
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetFileName((std::filesystem::path(folder) / name.str()).string().c_str());
    writer->SetInputData(&image);
    if (writer->Write() != 1)
        insitu::fail<insitu::IoError>("cannot write ", folder, "/", name.str());
    pvd << "    <DataSet timestep=\"" << step << "\" part=\"0\" file=\"" << name.str() << "\"/>\n";
}

int run(const Options& options) {
    insitu::InstrumentConfig config =
        options.config_path.empty() ? default_config()
                                    : insitu::InstrumentConfig::from_json_file(options.config_path);
    config.archive = options.archive;
    config.every = options.every;
    config.steps.clear();
    insitu::Instrument instrument(config);

    std::ofstream pvd;
    if (!options.vti_folder.empty()) {
        std::filesystem::create_directories(options.vti_folder);
        pvd.open(std::filesystem::path(options.vti_folder) / "heat.pvd");
        pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n"
            << "  <Collection>\n";
    }
    HeatSimulation simulation(options.size);
    for (int step = 1; step <= options.steps; ++step) {
        simulation.step(step);
        // Zero copy: the Field views the vtkFloatArray; the ghost layer comes from vtkGhostType.
        const insitu::vtk::VtkField temperature =
            insitu::vtk::to_field(simulation.image(), {"temperature"});
        instrument.execute(step, step, {temperature.field()});
        if (pvd.is_open() && config.selects(step)) {
            write_vti(options.vti_folder, step, simulation.image(), pvd);
        }
    }
    if (pvd.is_open()) pvd << "  </Collection>\n</VTKFile>\n";
    if (instrument.finalize() == insitu::Status::error || instrument.statistics().errors > 0) {
        std::cerr << "vtk-heat: " << instrument.statistics().errors
                  << " step(s) failed, last: " << instrument.last_error() << "\n";
        return 1;
    }
    std::cout << "vtk-heat: " << instrument.statistics() << " -> " << config.archive << "\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    // --help anywhere, before any value is parsed.
    if (insitu::cli::answer_help(insitu::cli::program_arguments(argc, argv), command_help())) {
        return 0;
    }
    Options options;
    try {
        options = parse(argc, argv);
    } catch (const UsageError& error) {
        std::cerr << "vtk-heat: " << error.what() << "\n";
        return 2;
    }
    try {
        return run(options);
    } catch (const std::exception& error) {
        std::cerr << "vtk-heat: " << insitu::one_line(error.what()) << "\n";
        // A bad configuration is the user's (2); files, devices and the rest are runtime
        // failures (1).
        const insitu::ErrorKind kind = insitu::classify(std::current_exception());
        const bool bad_input =
            kind == insitu::ErrorKind::invalid_argument || kind == insitu::ErrorKind::parse;
        return bad_input ? 2 : 1;
    }
}
