// insitu-view: explores a proxy archive without the volume (seed 000 §4-§6).
//
//   insitu-view info ARCHIVE [--json]
//   insitu-view render ARCHIVE --step N [--view V] [--azimuth DEG --elevation DEG]
//               [--tf TF.json | --opacity-scale J=S,...] [--colour auto|model|recompose]
//               [--source auto|single|multi]
//               [--light AZ,EL[,DIFFUSE[,SPECULAR]] | --light camera]... [--ambient A]
//               [--ao] [--ao-radius PIXELS] [--ao-strength S] [--enhance LAMBDA,GAMMA]
//               [--fill PIXELS] [--mask OUT.png] --out OUT.png|exr
//   insitu-view verify ARCHIVE
//   insitu-view serve ARCHIVE [--port P] [--bind ADDR]
//
// Exit status: 0 on success; 1 when verify finds problems or on failures that are not the
// user's input (no OpenCL platform, a failed kernel); 2 for bad arguments and bad input (unknown
// flag, malformed value, missing archive, step or view). Every failure is one line on stderr
// naming the offending flag or value.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli.hpp"
#include "explore_options.hpp"
#include "insitu/core/image.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/explorer.hpp"
#include "server.hpp"

namespace {

constexpr const char* kProgram = "insitu-view";
/// verify's status when it finds problems (as for runtime failures).
constexpr int kExitProblems = insitu::cli::kExitRuntimeError;
using insitu::cli::UsageError;

void print_help(std::ostream& out) {
    out << "usage:\n"
           "  insitu-view info ARCHIVE [--json]\n"
           "  insitu-view render ARCHIVE --step N [--view V] [--azimuth DEG --elevation DEG]\n"
           "      [--tf TF.json | --opacity-scale J=S,...] [--colour auto|model|recompose]\n"
           "      [--source auto|single|multi]\n"
           "      [--light AZ,EL[,DIFFUSE[,SPECULAR]] | --light camera]... [--ambient A]\n"
           "      [--ao] [--ao-radius PIXELS] [--ao-strength S] [--enhance LAMBDA,GAMMA]\n"
           "      [--fill PIXELS] [--mask OUT.png] --out OUT.png|exr\n"
           "  insitu-view verify ARCHIVE\n"
           "  insitu-view serve ARCHIVE [--port P] [--bind ADDR]\n";
}

std::string read_text_file(const std::string& flag, const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw UsageError(flag + ": cannot read \"" + path + "\"");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

int run_info(const std::vector<std::string>& args) {
    std::string archive;
    bool json = false;
    for (const std::string& arg : args) {
        if (arg == "--json") {
            json = true;
        } else if (arg.rfind("--", 0) == 0) {
            throw UsageError("info: unknown flag " + arg);
        } else if (archive.empty()) {
            archive = arg;
        } else {
            throw UsageError("info: unexpected argument \"" + arg + "\"");
        }
    }
    if (archive.empty()) throw UsageError("info: missing ARCHIVE");
    const insitu::ArchiveReader reader(archive);
    const nlohmann::json description = insitu::describe_archive(reader);
    if (json) {
        std::cout << description.dump(2) << "\n";
        return 0;
    }
    const auto& steps = description.at("steps");
    std::cout << "archive       " << archive << "\n"
              << "steps         " << steps.size();
    if (!steps.empty()) std::cout << " (" << steps.front() << " .. " << steps.back() << ")";
    std::cout << "\nviews         " << description.at("view_count") << "\n"
              << "bytes         " << description.at("bytes") << "\n"
              << "parts         " << description.at("parts").dump() << "\n";
    for (const auto& view : description.at("views")) {
        for (const char* perspective : {"single", "multi"}) {
            if (!view.contains(perspective)) continue;
            const auto& entry = view.at(perspective);
            std::cout << "view " << view.at("view") << " " << perspective << "  "
                      << entry.at("size")[0] << "x" << entry.at("size")[1] << " "
                      << entry.at("projection").get<std::string>() << ", azimuth "
                      << entry.at("azimuth") << ", elevation " << entry.at("elevation")
                      << ", layers " << entry.at("depth_layers") << " at "
                      << entry.at("isovalues").dump() << ", attenuation "
                      << (entry.at("attenuation").get<bool>() ? "yes" : "no");
            if (entry.contains("intervals")) {
                std::cout << " (" << entry.at("intervals").dump() << ")";
            }
            if (entry.contains("colour_model")) {
                std::cout << ", colour model L=" << entry.at("colour_model").at("intervals")
                          << " K=" << entry.at("colour_model").at("clusters");
            }
            if (entry.contains("distortion_tilt")) {
                std::cout << ", tilt " << entry.at("distortion_tilt") << " deg";
            }
            std::cout << "\n";
        }
    }
    std::cout << "configuration " << description.at("configuration").dump() << "\n";
    return 0;
}

int run_render(const std::vector<std::string>& args) {
    std::string archive, out_path, mask_path;
    insitu::viewer::Options options;
    std::string ao_radius, ao_strength;
    bool ao = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
        const std::string& arg = args[i];
        if (arg.rfind("--", 0) != 0) {
            if (!archive.empty()) throw UsageError("render: unexpected argument \"" + arg + "\"");
            archive = arg;
            continue;
        }
        if (arg == "--ao") {
            ao = true;
            continue;
        }
        if (i + 1 >= args.size()) throw UsageError(arg + ": missing value");
        const std::string& value = args[++i];
        const std::string key = arg.substr(2);
        if (key == "out") {
            out_path = value;
        } else if (key == "mask") {
            mask_path = value;
        } else if (key == "tf") {
            options["tf"] = read_text_file(arg, value);
        } else if (key == "light") {
            // Repeated --light flags add lights.
            auto& lights = options["light"];
            lights += (lights.empty() ? "" : ";") + value;
        } else if (key == "ao-radius") {
            ao_radius = value;
        } else if (key == "ao-strength") {
            ao_strength = value;
        } else {
            const auto& known = insitu::viewer::explore_option_keys();
            if (std::find(known.begin(), known.end(), key) == known.end() || key == "ao") {
                throw UsageError("render: unknown flag " + arg);
            }
            options[key] = value;
        }
    }
    if (archive.empty()) throw UsageError("render: missing ARCHIVE");
    if (options.find("step") == options.end()) throw UsageError("render: missing --step N");
    if (out_path.empty()) throw UsageError("render: missing --out OUT.png|exr");
    if (ao || !ao_radius.empty() || !ao_strength.empty()) {
        options["ao"] =
            (ao_radius.empty() ? "8" : ao_radius) + (ao_strength.empty() ? "" : "," + ao_strength);
    }
    const insitu::ExploreRequest request = insitu::viewer::request_from_options(options);
    insitu::Explorer explorer(archive);
    const insitu::ExploreFrame frame = explorer.render(request);
    insitu::write_image(out_path, frame.colour);
    if (!mask_path.empty()) insitu::write_image(mask_path, frame.confidence);
    std::cerr << kProgram << ": " << out_path << " (" << frame.camera.width() << "x"
              << frame.camera.height() << ", " << (frame.synthesised_view ? "new" : "stored")
              << " view, colour by " << insitu::to_string(frame.colour_source) << ", "
              << frame.milliseconds << " ms)\n";
    return 0;
}

int run_verify(const std::vector<std::string>& args) {
    if (args.size() != 1 || args[0].rfind("--", 0) == 0) {
        throw UsageError("verify: expected exactly one ARCHIVE");
    }
    const insitu::ArchiveReader reader(args[0]);
    const std::vector<std::string> problems = reader.verify();
    for (const std::string& problem : problems) std::cout << problem << "\n";
    std::size_t files = 0;
    for (const auto& step : reader.manifest().at("steps")) {
        for (const auto& view : step.at("views")) files += view.at("files").size();
    }
    std::cout << args[0] << ": " << files << " files checked, " << problems.size() << " problem"
              << (problems.size() == 1 ? "" : "s") << "\n";
    return problems.empty() ? 0 : kExitProblems;
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::string> all(argv + 1, argv + argc);
    if (all.empty()) {
        return insitu::cli::report(
            kProgram, "missing command (info, render, verify or serve; --help for usage)",
            insitu::cli::kExitBadInput);
    }
    if (all[0] == "--help" || all[0] == "-h" || all[0] == "help") {
        print_help(std::cout);
        return 0;
    }
    const std::string command = all[0];
    const std::vector<std::string> args(all.begin() + 1, all.end());
    return insitu::cli::run_reporting(kProgram, [&] {
        if (command == "info") return run_info(args);
        if (command == "render") return run_render(args);
        if (command == "verify") return run_verify(args);
        if (command == "serve") return insitu::viewer::serve_main(args);
        throw UsageError("unknown command \"" + command +
                         "\" (expected info, render, verify or serve)");
    });
}
