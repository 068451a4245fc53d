// gray-scott-mpi-compare: whether two timestep proxy archives hold the same proxies, step by
// step and view by view: the same run on 1 rank and on N, say, which a distributed Instrument
// must make agree up to the order in which the ranks' partial images are blended. Prints the
// largest difference of every proxy (depth layers, distortion layers, attenuation, mean and
// optical depth, the layers' isovalues and the intervals) and of the preview per step and view,
// with where it is when it exceeds its tolerance, then one verdict line: a command line over
// insitu::compare_archives (insitu/testing/archive_comparison.hpp), which says what is left out.
//
//   gray-scott-mpi-compare ONE.cdb OTHER.cdb [--attenuation-tolerance A] [--depth-tolerance R]
//
// Exit status: 0 every difference within its tolerance, 1 one beyond (or a step, view or image
// that one archive has and the other not), 2 bad arguments or an archive that cannot be read.
#include <iostream>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "cli.hpp"
#include "insitu/error.hpp"
#include "insitu/testing/archive_comparison.hpp"

namespace {

constexpr const char* kProgram = "gray-scott-mpi-compare";

using insitu::cli::UsageError;

struct Arguments {
    std::vector<std::string> archives;
    insitu::ArchiveTolerances tolerances;  // the defaults are explained there
};

const std::vector<insitu::cli::TableOption<Arguments>>& option_table() {
    using V = const std::string&;
    const auto tolerance = [](V flag, V value) {
        const double parsed = insitu::cli::parse_finite(flag, value);
        if (parsed < 0.0) throw UsageError(flag + " " + value + ": must be >= 0");
        return parsed;
    };
    static const std::vector<insitu::cli::TableOption<Arguments>> table = {
        {"--attenuation-tolerance", "A", false,
         "largest absolute difference of attenuation a_j (a fraction)", "1e-4",
         [=](Arguments& a, V f, V v) { a.tolerances.attenuation = tolerance(f, v); }},
        {"--depth-tolerance", "R", false,
         "largest relative difference of depth layers, distortion, mean and optical depth "
         "(relative to the larger magnitude, at least 1)",
         "1e-3", [=](Arguments& a, V f, V v) { a.tolerances.depth = tolerance(f, v); }},
        {"--preview-tolerance", "P", false,
         "largest absolute difference of the previews' linear, premultiplied values", "0.02",
         [=](Arguments& a, V f, V v) { a.tolerances.preview = tolerance(f, v); }},
        {"--value-tolerance", "R", false,
         "largest relative difference of isovalues and interval edges (at least 1)", "1e-6",
         [=](Arguments& a, V f, V v) { a.tolerances.value = tolerance(f, v); }},
    };
    return table;
}

const insitu::cli::CommandHelp& command_help() {
    static const insitu::cli::CommandHelp help = [] {
        insitu::cli::CommandHelp h;
        h.usage = std::string(kProgram) + " ONE.cdb OTHER.cdb [options]";
        h.description =
            "Compares two timestep proxy archives step by step and view by view (a run of "
            "gray-scott-mpi on 1 rank and on N): prints the largest difference of every proxy and "
            "of the previews, and fails when one exceeds its tolerance.";
        h.options = insitu::cli::help_rows(option_table());
        h.notes =
            "Exit status: 0 within tolerance, 1 a difference beyond it or a step, view or image "
            "only one archive has, 2 bad arguments or an unreadable archive.";
        return h;
    }();
    return help;
}

int compare(const Arguments& arguments) {
    const insitu::ArchiveComparison comparison = insitu::compare_archives(
        arguments.archives[0], arguments.archives[1], arguments.tolerances);
    for (const std::string& problem : comparison.problems) {
        std::cerr << kProgram << ": " << problem << std::endl;
    }
    for (const insitu::FrameComparison& frame : comparison.frames) {
        std::cout << "step " << frame.step << " view " << frame.view << " " << frame.perspective
                  << ":";
        for (const insitu::ProxyMeasurement& measurement : frame.measurements) {
            std::cout << "  " << measurement;
        }
        std::cout << std::endl;
    }
    std::cout << kProgram << ": " << comparison << std::endl;
    const int failed = comparison.failures();
    if (failed > 0 || comparison.frames.empty()) {
        std::cerr << kProgram << ": " << failed << " difference(s) beyond tolerance between "
                  << arguments.archives[0] << " and " << arguments.archives[1] << std::endl;
        return insitu::cli::kExitRuntimeError;
    }
    std::cout << kProgram << ": all within tolerance" << std::endl;
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    return insitu::cli::run_command(
        kProgram, insitu::cli::program_arguments(argc, argv), command_help(), [&] {
            Arguments arguments;
            insitu::cli::parse_table(argc, argv, option_table(), arguments, &arguments.archives);
            if (arguments.archives.size() != 2) {
                throw UsageError("expected two archives, got " +
                                 std::to_string(arguments.archives.size()) + " (see --help)");
            }
            return compare(arguments);
        });
}
