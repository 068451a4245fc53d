#include "export_command.hpp"

#include <fstream>
#include <iostream>
#include <sstream>

#include "cli.hpp"
#include "insitu/error.hpp"
#include "static_site.hpp"

namespace insitu::viewer {
namespace {

namespace fs = std::filesystem;
using cli::UsageError;

struct Arguments {
    std::vector<std::string> positional;
    ExportOptions options;
};

/// "N[k|M|G][B]": bytes, in powers of 1000 (a 50 MB supplementary limit is --max-bytes 50M).
std::uintmax_t parse_bytes(const std::string& flag, const std::string& text) {
    std::string digits = text;
    if (!digits.empty() && (digits.back() == 'B' || digits.back() == 'b')) digits.pop_back();
    std::uintmax_t unit = 1;
    if (!digits.empty()) {
        const char last = digits.back();
        unit = last == 'k' || last == 'K' ? 1000
               : last == 'M'              ? 1000'000
               : last == 'G'              ? 1000'000'000
                                          : 1;
        if (unit > 1) digits.pop_back();
    }
    std::uintmax_t value = 0;
    if (cli::convert_integer(digits, value) != std::errc() || value < 1 ||
        value > UINTMAX_MAX / unit) {
        throw UsageError(flag + " " + text + ": not a positive number of bytes (N, Nk, NM or NG)");
    }
    return value * unit;
}

/// "A,B,C": integers, each in [minimum, maximum].
template <typename Integer>
std::vector<Integer> parse_list(const std::string& flag, const std::string& text, Integer minimum) {
    std::vector<Integer> values;
    std::stringstream parts(text);
    std::string part;
    while (std::getline(parts, part, ',')) {
        values.push_back(cli::parse_integer<Integer>(flag, part, minimum,
                                                     std::numeric_limits<Integer>::max(), text));
    }
    if (values.empty() || text.back() == ',') {
        throw UsageError(flag + " \"" + text + "\": expected a comma-separated list");
    }
    return values;
}

const std::vector<cli::TableOption<Arguments>>& option_table() {
    using V = const std::string&;
    static const std::vector<cli::TableOption<Arguments>> table = {
        {"--steps", "S,S,...", false, "the steps to export", "every step",
         [](Arguments& a, V f, V v) {
             a.options.steps =
                 parse_list<std::int64_t>(f, v, std::numeric_limits<std::int64_t>::lowest());
         }},
        {"--views", "V,V,...", false, "the views to export", "every view",
         [](Arguments& a, V f, V v) { a.options.views = parse_list<int>(f, v, 0); }},
        {"--max-bytes", "N", false,
         "the site at most N bytes (k, M, G: powers of 1000): where the run does not fit, its "
         "light fields are left out (the largest, least accurate per byte), then steps, evenly "
         "over the run; each listed; an error when no step fits",
         "no limit", [](Arguments& a, V f, V v) { a.options.max_bytes = parse_bytes(f, v); }},
        {"--replace", nullptr, false,
         "replace OUT where it exists (only an empty folder or a gallery export wrote)",
         "refuse an existing OUT", [](Arguments& a, V, V) { a.options.replace = true; }},
    };
    return table;
}

}  // namespace

const cli::CommandHelp& export_help() {
    static const cli::CommandHelp help = [] {
        cli::CommandHelp h;
        h.usage =
            "insitu-view export ARCHIVE... OUT [--steps S,...] [--views V,...] [--max-bytes N] "
            "[--replace]";
        h.description =
            "Writes ARCHIVE as a static web gallery in the folder OUT: the web viewer's page and, "
            "per step, the data it draws from (light field, proxies, compressed field, the "
            "stored frame, recipes, trusted range), an index, README.txt (how to host it) and the "
            "run's Cinema database (data.csv, previews). Any static web server shows it (python3 "
            "-m http.server); nothing runs server-side. Damaged steps are left out and listed. "
            "With several archives, OUT is a gallery of the runs: OUT/NAME/ each run's site "
            "(NAME: its folder's name), OUT/index.html their thumbnails, steps and sizes, each "
            "--max-bytes an equal share.";
        h.options = cli::help_rows(option_table());
        h.notes =
            "Exit status: 0 written, 3 written with damaged steps left out (listed on stdout), 2 "
            "bad arguments, an existing OUT without --replace, a --max-bytes no step fits in or "
            "an unreadable archive, 1 other failures.";
        return h;
    }();
    return help;
}

int export_main(const std::vector<std::string>& args) {
    std::vector<std::string> words{"export"};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& word : words) argv.push_back(word.data());
    Arguments arguments;
    cli::parse_table(static_cast<int>(argv.size()), argv.data(), option_table(), arguments,
                     &arguments.positional);
    if (arguments.positional.size() < 2) {
        throw UsageError("export: expected ARCHIVE... and OUT, got " +
                         std::to_string(arguments.positional.size()) + " argument(s)");
    }
    std::vector<std::string> archives = arguments.positional;
    arguments.options.out = archives.back();
    archives.pop_back();
    std::vector<ExportReport> reports;
    if (archives.size() == 1) {
        arguments.options.archive = archives.front();
        reports.push_back(export_site(arguments.options));
    } else {
        reports = export_gallery(archives, arguments.options);
    }
    bool damaged = false;
    for (std::size_t r = 0; r < reports.size(); ++r) {
        const ExportReport& report = reports[r];
        const fs::path site =
            archives.size() == 1
                ? arguments.options.out
                : arguments.options.out / fs::absolute(archives[r]).lexically_normal().filename();
        std::cout << site.string() << ": " << report.steps.size() << " step"
                  << (report.steps.size() == 1 ? "" : "s") << ", " << report.files << " files, "
                  << report.bytes << " bytes\n";
        for (const auto& [step, why] : report.left_out) {
            std::cout << "left out: step " << step << ": " << why << "\n";
            damaged = damaged || why.rfind("damaged", 0) == 0;
        }
        for (const std::string& what : report.omitted) std::cout << "left out: " << what << "\n";
    }
    return damaged ? cli::kExitDamagedInput : 0;
}

}  // namespace insitu::viewer
