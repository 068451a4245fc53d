#include "compare_command.hpp"

#include <iostream>
#include <optional>

#include "cli.hpp"
#include "insitu/archive/archive_reader.hpp"
#include "insitu/testing/archive_comparison.hpp"

namespace insitu::viewer {

namespace {

using cli::UsageError;

struct Arguments {
    std::vector<std::string> archives;
    // Given on the command line: replace the defaults (the stored step is added all the same).
    std::optional<double> attenuation, depth, preview, value;
    bool all = false;
};

const std::vector<cli::TableOption<Arguments>>& option_table() {
    using V = const std::string&;
    const auto tolerance = [](V flag, V value) {
        const double parsed = cli::parse_finite(flag, value);
        if (parsed < 0.0) throw UsageError(flag + " " + value + ": must be >= 0");
        return parsed;
    };
    static const std::vector<cli::TableOption<Arguments>> table = {
        {"--attenuation-tolerance", "A", false,
         "largest absolute difference of attenuation a_j (a fraction), before the stored step",
         "1e-4", [=](Arguments& a, V f, V v) { a.attenuation = tolerance(f, v); }},
        {"--depth-tolerance", "R", false,
         "largest relative difference of depth layers, distortion, mean and optical depth "
         "(relative to the larger magnitude, at least 1), before the stored step",
         "1e-3", [=](Arguments& a, V f, V v) { a.depth = tolerance(f, v); }},
        {"--preview-tolerance", "P", false,
         "largest absolute difference of the previews' linear, premultiplied values", "0.02",
         [=](Arguments& a, V f, V v) { a.preview = tolerance(f, v); }},
        {"--value-tolerance", "R", false,
         "largest relative difference of isovalues and interval edges (at least 1)", "1e-6",
         [=](Arguments& a, V f, V v) { a.value = tolerance(f, v); }},
        {"--all", nullptr, false, "print every frame's largest differences, not only failures",
         "failures only", [](Arguments& a, V, V) { a.all = true; }},
    };
    return table;
}

ArchiveTolerances tolerances_for(const Arguments& arguments, const ArchiveReader& one,
                                 const ArchiveReader& other) {
    ArchiveTolerances tolerances = ArchiveTolerances::for_archives(one, other);
    if (arguments.attenuation) tolerances.attenuation = *arguments.attenuation;
    if (arguments.depth) tolerances.depth = *arguments.depth;
    if (arguments.preview) tolerances.preview = *arguments.preview;
    if (arguments.value) tolerances.value = *arguments.value;
    return tolerances;
}

int compare(const Arguments& arguments) {
    const std::string& first = arguments.archives[0];
    const std::string& second = arguments.archives[1];
    const ArchiveTolerances tolerances =
        tolerances_for(arguments, ArchiveReader(first), ArchiveReader(second));
    std::cout << "tolerances: " << to_string(tolerances) << "\n";
    const ArchiveComparison comparison = compare_archives(first, second, tolerances);
    for (const std::string& problem : comparison.problems) std::cout << problem << "\n";
    for (const FrameComparison& frame : comparison.frames) {
        bool failed = false;
        for (const ProxyMeasurement& measurement : frame.measurements) {
            failed = failed || !measurement.passed();
        }
        if (!failed && !arguments.all) continue;
        std::cout << "step " << frame.step << " view " << frame.view << " " << frame.perspective
                  << ":";
        for (const ProxyMeasurement& measurement : frame.measurements) {
            std::cout << "  " << measurement;
        }
        std::cout << "\n";
    }
    std::cout << comparison << "\n";
    if (comparison.frames.empty() && comparison.problems.empty()) {
        std::cerr << "insitu-view: compare: " << first << " and " << second
                  << " hold no steps to compare\n";
        return cli::kExitRuntimeError;
    }
    const int failed = comparison.failures();
    if (failed > 0) {
        std::cerr << "insitu-view: compare: " << failed
                  << " difference(s) beyond tolerance between " << first << " and " << second
                  << "\n";
        return cli::kExitRuntimeError;
    }
    std::cout << "all within tolerance\n";
    return 0;
}

}  // namespace

const cli::CommandHelp& compare_help() {
    static const cli::CommandHelp help = [] {
        cli::CommandHelp h;
        h.usage = "insitu-view compare ONE.cdb OTHER.cdb [options]";
        h.description =
            "Compares two archives of the same run (on 1 rank and on N, before and after a "
            "change) step by step and view by view: prints the tolerances, the frames whose "
            "proxies or previews differ beyond them, and the largest difference of every "
            "quantity. Channels stored at the archive's \"precision\" (attenuation, mean and "
            "optical depth) are allowed one step of it more: 2^-11 for half (values that round "
            "either side of a step), 2^-24 for float; a budget that chooses the precision counts "
            "as half.";
        h.options = cli::help_rows(option_table());
        h.notes =
            "Exit status: 0 within tolerance, 1 a difference beyond it (or a step, view or "
            "image only one archive has, or nothing to compare), 2 bad arguments or an "
            "unreadable archive.";
        return h;
    }();
    return help;
}

int compare_main(const std::vector<std::string>& args) {
    // parse_table reads an argv; the first entry stands for the command.
    std::vector<std::string> words{"compare"};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& word : words) argv.push_back(word.data());
    Arguments arguments;
    cli::parse_table(static_cast<int>(argv.size()), argv.data(), option_table(), arguments,
                     &arguments.archives);
    if (arguments.archives.size() != 2) {
        throw UsageError("compare: expected two archives, got " +
                         std::to_string(arguments.archives.size()));
    }
    return compare(arguments);
}

}  // namespace insitu::viewer
