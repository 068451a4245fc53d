// insitu-view: explores a proxy archive without the volume (seed 000 §4-§6).
//
//   insitu-view info ARCHIVE [--json]
//   insitu-view render ARCHIVE --step N [--view V] [--azimuth DEG --elevation DEG]
//               [--tf TF.json | --opacity-scale J=S,...] [--colour auto|model|recompose]
//               [--segment-opacity S=F,...] [--source auto|single|multi|lightfield|volume]
//               [--light AZ,EL[,DIFFUSE[,SPECULAR]] | --light camera]... [--ambient A]
//               [--ao] [--ao-radius PIXELS] [--ao-strength S] [--enhance LAMBDA,GAMMA]
//               [--fill PIXELS] [--mask OUT.png] --out OUT.png|exr
//   insitu-view verify ARCHIVE
//   insitu-view compare ONE.cdb OTHER.cdb [--attenuation-tolerance A] [--depth-tolerance R] ...
//   insitu-view serve ARCHIVE [--port P] [--bind ADDR]
//   insitu-view export ARCHIVE... OUT [--steps S,...] [--views V,...] [--max-bytes N] [--replace]
//   insitu-view COMMAND --help      (or -h, anywhere among the arguments; or: help COMMAND)
//
// info and verify read damaged archives too: info shows what can be read and lists the damage
// under "damage:", verify lists every problem; only a directory with no readable index at all is
// refused.
//
// Exit status (tools/cli.hpp): 0 on success (and for --help); 3 when info or verify found damage
// (what could be read was shown, every problem listed on stdout, one line on stderr says so); 2
// for bad arguments and bad input (unknown flag, malformed value, missing archive, step or view,
// an archive with no readable index); 1 on failures that are not the user's input (no OpenCL
// platform, a failed kernel). Every failure is one line on stderr naming the offending flag or
// value.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "archive_inspection.hpp"
#include "arguments.hpp"
#include "cli.hpp"
#include "compare_command.hpp"
#include "explore_options.hpp"
#include "export_command.hpp"
#include "insitu/archive/archive_reader.hpp"
#include "insitu/core/image.hpp"
#include "insitu/error.hpp"
#include "insitu/explore/explorer.hpp"
#include "server.hpp"

namespace {

constexpr const char* kProgram = "insitu-view";
using insitu::cli::CommandHelp;
using insitu::cli::default_text;
using insitu::cli::OptionHelp;
using insitu::cli::UsageError;

const CommandHelp& info_help() {
    static const CommandHelp help{
        "insitu-view info ARCHIVE [--json]",
        "Describes ARCHIVE: its steps, views, proxies, light fields, what an error budget chose "
        "at each step, and its configuration. Every file is checked "
        "against the index (size, CRC-32); of a damaged archive it shows what can be read and "
        "lists each problem, one line each naming the file, under \"damage:\".",
        {{"--json", "",
          "print the description as JSON (as the web viewer's /api/archive), with "
          "\"damage\" and \"unreadable\" (step, view) lists",
          "text"}},
        "Exit status: 0 for a sound archive, 3 when damage was found (what can be read is still "
        "shown), 2 for bad arguments or a directory with no readable index."};
    return help;
}

const CommandHelp& verify_help() {
    static const CommandHelp help{
        "insitu-view verify ARCHIVE",
        "Checks every file the index names (present, inside the archive, size and CRC-32 as "
        "recorded), the index itself (manifest.json, manifest.journal, malformed step entries) "
        "and data.csv against it, and lists every problem, one line each.",
        {},
        "Exit status: 0 when the archive is intact, 3 when problems were found, 2 for bad "
        "arguments or a directory with no readable index."};
    return help;
}

/// render's flags. Each one with a value is the explore option of its name
/// (explore_options.hpp) except --out, --mask, --tf (a file, read here), --light (repeatable)
/// and --ao-radius/--ao-strength (folded into the "ao" option).
const std::vector<OptionHelp>& render_options() {
    static const std::vector<OptionHelp> options{
        {"--step", "N", "the step to show", "", true},
        {"--view", "V", "the stored view to start from", "0"},
        {"--azimuth", "DEG", "orbit azimuth of a new view, in degrees", "the stored view's"},
        {"--elevation", "DEG", "orbit elevation of a new view, in degrees in [-90, 90]",
         "the stored view's"},
        {"--tf", "TF.json",
         "an edited transfer function (DESIGN.md TF JSON) over the stored one's value range",
         "the stored one"},
        {"--opacity-scale", "J=S,...", "scale interval J's opacity by S >= 0", "none"},
        {"--colour", "auto|model|recompose",
         "colour by the fitted colour model or by exact recomposition; auto takes the model when "
         "the archive has one and the colours are unchanged",
         "auto"},
        {"--segment-opacity", "S=F,...",
         "scale light-field segment S's opacity by F >= 0 (seed 001's per-layer fades)", "none"},
        {"--source", "auto|single|multi|lightfield|volume",
         "what a new view is made from; auto: the stored view's proxies at the stored view, "
         "elsewhere the step's compressed field where it has one (volume: the ground truth of "
         "the decoded field), else the light field and the view's proxies fused per pixel "
         "where the step has a light field, else the single-perspective proxies",
         "auto"},
        {"--light", "AZ,EL[,DIFFUSE[,SPECULAR]]|camera",
         "a directional light toward orbit angles AZ, EL in degrees (world space), DIFFUSE " +
             default_text(insitu::Light{}.diffuse) + " and SPECULAR " +
             default_text(insitu::Light{}.specular) +
             " unless given, or camera: a headlight; repeat for more lights",
         "unlit"},
        {"--ambient", "A", "ambient term of the lighting, >= 0",
         default_text(insitu::LightingSettings{}.ambient)},
        {"--ao", "", "proxy ambient occlusion (Eq. 5)", ""},
        {"--ao-radius", "PIXELS", "ambient occlusion radius in pixels, 1..64; implies --ao",
         default_text(insitu::AmbientOcclusionSettings{}.radius_pixels)},
        {"--ao-strength", "S", "ambient occlusion strength, >= 0; implies --ao",
         default_text(insitu::AmbientOcclusionSettings{}.strength)},
        {"--enhance", "LAMBDA,GAMMA", "depth-aware enhancement (Eq. 11), LAMBDA >= 0, GAMMA > 0",
         "off"},
        {"--fill", "PIXELS", "hole-filling radius of view synthesis in pixels, 0..16",
         default_text(insitu::SynthesisSettings{}.hole_fill_radius_pixels)},
        {"--mask", "OUT.png",
         "also write the confidence mask (1: stored or well supported, 0: a hole)", "none"},
        {"--out", "OUT.png|exr", "the image: 8-bit sRGB PNG or linear premultiplied EXR", "", true},
    };
    return options;
}

const CommandHelp& render_help() {
    static const CommandHelp help{
        "insitu-view render ARCHIVE --step N --out OUT.png|exr [options]",
        "Renders one frame from the stored proxies of a step, without the volume: the stored "
        "view or a new one, with an edited transfer function, lighting, ambient occlusion and "
        "enhancement (the pixels the web viewer shows for the same options).",
        render_options(),
        "Exit status: 0 success, 2 bad arguments or input (unknown flag, malformed value, "
        "missing archive, step or view), 1 other failures (no OpenCL device)."};
    return help;
}

std::string read_text_file(const std::string& flag, const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw UsageError(flag + ": cannot read \"" + path + "\"");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

/// info's and verify's last word on a damaged archive: one line on stderr, the damage status.
int report_damage(const std::string& archive, std::size_t problems, const char* where) {
    return insitu::cli::report(kProgram,
                               "\"" + archive + "\" is damaged: " + std::to_string(problems) +
                                   " problem" + (problems == 1 ? "" : "s") + " " + where,
                               insitu::cli::kExitDamagedInput);
}

/// The (step, view) entries left out, "step 8 view 0, step 12 view 1".
std::string entries_text(const std::set<std::pair<std::int64_t, int>>& entries) {
    std::string text;
    for (const auto& [step, view] : entries) {
        text += (text.empty() ? "" : ", ") + std::string("step ") + std::to_string(step) +
                " view " + std::to_string(view);
    }
    return text;
}

/// info --json: the archive's description with its damage and unreadable entries.
int print_info_json(const std::string& archive,
                    const insitu::viewer::ArchiveInspection& inspection) {
    const std::vector<std::string>& damage = inspection.damage;
    nlohmann::json output = inspection.description;
    output["damage"] = damage;
    output["unreadable"] = nlohmann::json::array();
    for (const auto& [step, view] : inspection.unreadable) {
        output["unreadable"].push_back({{"step", step}, {"view", view}});
    }
    output["manifest_readable"] = inspection.manifest_readable;
    std::cout << output.dump(2) << "\n";
    return damage.empty() ? 0 : report_damage(archive, damage.size(), "(\"damage\")");
}

/// info's line per view and perspective: size, projection, camera, layers, attenuation.
void print_views(const nlohmann::json& description) {
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
}

/// info's line per light field: its rig, segments, attenuation and depth precision.
void print_light_fields(const nlohmann::json& description) {
    for (const auto& light_field : description.at("light_fields")) {
        std::cout << "light field   " << light_field.at("field").get<std::string>() << ": "
                  << light_field.at("cameras") << " cameras, " << light_field.at("map_size")
                  << "^2 maps, " << light_field.at("segments") << " segment(s), attenuation "
                  << (light_field.at("attenuation").get<bool>() ? "yes" : "no") << ", depth "
                  << light_field.at("depth_bits") << " bits\n";
    }
}

/// info's line per field with a compressed field: its codec and tolerance or rate, and its
/// bytes and ratio to the raw floats, over the steps that have it.
void print_volumes(const nlohmann::json& description) {
    std::map<std::string, std::vector<const nlohmann::json*>> by_field;
    for (const auto& volume : description.at("volumes")) {
        by_field[volume.at("field").get<std::string>()].push_back(&volume);
    }
    for (const auto& [field, volumes] : by_field) {
        const nlohmann::json& first = *volumes.front();
        double bytes = 0.0;
        double ratio = 0.0;
        for (const nlohmann::json* volume : volumes) {
            bytes += volume->at("bytes").get<double>();
            ratio += volume->at("ratio").get<double>();
        }
        const double steps = static_cast<double>(volumes.size());
        std::cout << "volume        " << field << ": " << first.at("codec").get<std::string>()
                  << " " << first.at("mode").get<std::string>() << " ";
        if (first.at("mode") == "rate") {
            std::cout << first.at("rate").get<double>() << " bits/value";
        } else {
            std::cout << "tolerance " << first.at("tolerance").get<double>() << " (range "
                      << first.at("min").get<double>() << ".." << first.at("max").get<double>()
                      << ")";
        }
        std::cout << ", " << first.at("dims")[0] << "x" << first.at("dims")[1] << "x"
                  << first.at("dims")[2] << ", " << volumes.size() << " step(s), "
                  << std::setprecision(3) << bytes / steps / 1e6 << " MB/step, ratio "
                  << std::setprecision(3) << ratio / steps << ":1\n"
                  << std::setprecision(6);
    }
}

/// A budget's measured PSNR as info prints it ("exact" where nothing was lost).
std::string budget_psnr_text(const nlohmann::json& value) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(1);
    if (value.is_null()) {
        text << "exact";
    } else {
        text << value.get<double>() << " dB";
    }
    return text.str();
}

/// Whether a budget's choice met its target, as info prints it.
const char* budget_met_text(const nlohmann::json& choice) {
    return choice.at("met").get<bool>() ? " met" : " NOT met";
}

/// What an error budget chose at each step: the views' intervals, precision and size, whether it
/// kept the compressed field, the light field's rig and the colour model's K, each with the PSNR
/// it measured.
void print_budget(const nlohmann::json& description) {
    for (const auto& entry : description.value("budget", nlohmann::json::array())) {
        std::cout << "budget        step " << entry.at("step") << " "
                  << entry.at("field").get<std::string>() << ": " << entry.at("intervals") << " "
                  << entry.at("mode").get<std::string>() << " intervals";
        if (entry.contains("precision")) {
            std::cout << ", " << entry.at("precision").get<std::string>();
        }
        if (entry.value("size_divisor", 1) != 1) std::cout << ", 1/" << entry.at("size_divisor");
        std::cout << ", " << budget_psnr_text(entry.at("psnr_db")) << budget_met_text(entry);
        if (entry.contains("light_field")) {
            const auto& light_field = entry.at("light_field");
            std::cout << "; light field " << light_field.at("cameras") << " cameras at "
                      << light_field.at("size") << "^2, "
                      << budget_psnr_text(light_field.at("psnr_db"))
                      << budget_met_text(light_field);
        }
        if (entry.contains("volume")) {
            const auto& volume = entry.at("volume");
            std::cout << "; compressed field at " << volume.at("relative_tolerance")
                      << " of the range, " << budget_psnr_text(volume.at("psnr_db"))
                      << (volume.at("met").get<bool>() ? " met: kept" : " NOT met: not kept");
        }
        if (entry.contains("colour_model")) {
            const auto& model = entry.at("colour_model");
            std::cout << "; colour model K=" << model.at("clusters") << ", "
                      << budget_psnr_text(model.at("psnr_db")) << budget_met_text(model);
        }
        std::cout << (entry.value("checked", false) ? "" : " (kept from the last check)") << "\n";
    }
}

/// info as text: a line per property, view, light field and budget check, then the damage.
int print_info_text(const std::string& archive,
                    const insitu::viewer::ArchiveInspection& inspection) {
    const nlohmann::json& description = inspection.description;
    const std::vector<std::string>& damage = inspection.damage;
    const auto& steps = description.at("steps");
    std::cout << "archive       " << archive << "\n"
              << "steps         " << steps.size();
    if (!steps.empty()) std::cout << " (" << steps.front() << " .. " << steps.back() << ")";
    std::cout << "\nviews         " << description.at("view_count") << "\n"
              << "bytes         " << description.at("bytes") << "\n"
              << "parts         " << description.at("parts").dump() << "\n";
    print_views(description);
    print_light_fields(description);
    print_volumes(description);
    print_budget(description);
    if (inspection.manifest_readable) {
        std::cout << "configuration " << description.at("configuration").dump() << "\n";
    } else {
        std::cout << "configuration unknown (manifest.json is unusable; steps from "
                     "manifest.journal)\n";
    }
    if (!inspection.unreadable.empty()) {
        std::cout << "unreadable    " << entries_text(inspection.unreadable) << "\n";
    }
    // info reads the index and each file's size, not the files (a long run opens in a second);
    // a file changed at its size is found by verify, or by the read that uses it.
    std::cout << "checked       index and file sizes (verify reads every byte)\n";
    if (damage.empty()) {
        std::cout << "damage        none\n";
        return 0;
    }
    std::cout << "damage:\n";
    for (const std::string& problem : damage)
        std::cout << "  " << insitu::one_line(problem) << "\n";
    return report_damage(archive, damage.size(), "(listed under \"damage:\")");
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
    const insitu::viewer::ArchiveInspection inspection = insitu::viewer::inspect_archive(archive);
    return json ? print_info_json(archive, inspection) : print_info_text(archive, inspection);
}

/// Refuses (UsageError) a flag that render does not list.
void require_render_flag(const std::string& flag) {
    const auto& options = render_options();
    if (std::none_of(options.begin(), options.end(),
                     [&](const OptionHelp& option) { return option.flag == flag; })) {
        throw UsageError("render: unknown flag " + flag);
    }
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
        require_render_flag(arg);
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
            options[key] = value;
        }
    }
    if (archive.empty()) throw UsageError("render: missing ARCHIVE");
    if (options.find("step") == options.end()) throw UsageError("render: missing --step N");
    if (out_path.empty()) throw UsageError("render: missing --out OUT.png|exr");
    if (ao || !ao_radius.empty() || !ao_strength.empty()) {
        options["ao"] =
            (ao_radius.empty() ? default_text(insitu::AmbientOcclusionSettings{}.radius_pixels)
                               : ao_radius) +
            (ao_strength.empty() ? "" : "," + ao_strength);
    }
    const insitu::ExploreRequest request = insitu::viewer::request_from_options(options);
    insitu::Explorer explorer(archive);
    const insitu::ExploreFrame frame = explorer.render(request);
    insitu::write_image(out_path, frame.colour);
    if (!mask_path.empty()) insitu::write_image(mask_path, frame.confidence);
    std::cerr << kProgram << ": " << out_path << " (" << frame.camera.width() << "x"
              << frame.camera.height() << ", " << (frame.synthesised_view ? "new" : "stored")
              << " view from " << insitu::to_string(frame.proxy_source) << ", colour by "
              << (frame.proxy_source == insitu::ProxySource::volume
                      ? std::string("the ground truth of the decoded field")
                      : insitu::to_string(frame.colour_source))
              << ", "
              << (frame.missing_cameras.empty()
                      ? std::string()
                      : std::to_string(frame.missing_cameras.size()) +
                            " light-field cameras missing (reconstructed from the rest), ")
              << frame.milliseconds << " ms)\n";
    if (!frame.note.empty()) std::cerr << kProgram << ": " << frame.note << "\n";
    return 0;
}

int run_verify(const std::vector<std::string>& args) {
    for (const std::string& arg : args) {
        if (arg.rfind("--", 0) == 0) throw UsageError("verify: unknown flag " + arg);
    }
    if (args.size() != 1) throw UsageError("verify: expected exactly one ARCHIVE");
    const insitu::ArchiveReader reader = insitu::ArchiveReader::open_damaged(args[0]);
    const std::vector<std::string> problems = reader.check().problems;
    for (const std::string& problem : problems) std::cout << insitu::one_line(problem) << "\n";
    std::size_t files = 0;
    for (const auto& step : reader.manifest().at("steps")) {
        for (const auto& view : step.at("views")) files += view.at("files").size();
        const std::int64_t number = step.at("step").get<std::int64_t>();
        files += reader.light_fields(number).size();
        for (const insitu::ArchivedVolume& volume : reader.volumes(number)) {
            files += volume.files.size();
        }
    }
    std::cout << args[0] << ": " << files << " files checked, " << problems.size() << " problem"
              << (problems.size() == 1 ? "" : "s") << "\n";
    return problems.empty() ? 0 : report_damage(args[0], problems.size(), "(listed on stdout)");
}

struct Command {
    const char* name;
    const CommandHelp& (*help)();
    int (*run)(const std::vector<std::string>& args);
};

const std::vector<Command>& commands() {
    static const std::vector<Command> table{
        {"info", info_help, run_info},
        {"render", render_help, run_render},
        {"verify", verify_help, run_verify},
        {"compare", insitu::viewer::compare_help, insitu::viewer::compare_main},
        {"serve", insitu::viewer::serve_help, insitu::viewer::serve_main},
        {"export", insitu::viewer::export_help, insitu::viewer::export_main}};
    return table;
}

const Command* find_command(const std::string& name) {
    for (const Command& command : commands()) {
        if (name == command.name) return &command;
    }
    return nullptr;
}

UsageError unknown_command(const std::string& name) {
    return UsageError("unknown command \"" + name +
                      "\" (expected info, render, verify, compare, serve or export)");
}

void print_help(std::ostream& out) {
    out << "usage: insitu-view COMMAND ARCHIVE [options]\n\n"
           "Explores a proxy archive without the volume.\n\n"
           "commands:\n";
    for (const Command& command : commands()) out << "  " << command.help().usage << "\n";
    out << "\n'insitu-view COMMAND --help' (or 'insitu-view help COMMAND') lists a command's\n"
           "options and their defaults.\n"
           "Exit status: 0 success, 2 bad arguments or input, 3 damage found by info or verify,\n"
           "1 other failures (and differences beyond tolerance found by compare).\n";
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::string> all = insitu::cli::program_arguments(argc, argv);
    if (all.empty()) {
        return insitu::cli::report(
            kProgram,
            "missing command (info, render, verify, compare, serve or export; --help for usage)",
            insitu::cli::kExitBadInput);
    }
    // "help [COMMAND]", "--help [COMMAND]": the overview, or the command's own help.
    if (all[0] == "help" || insitu::cli::is_help_flag(all[0])) {
        if (all.size() == 1) {
            print_help(std::cout);
            return 0;
        }
        const Command* command = find_command(all[1]);
        if (!command) {
            return insitu::cli::report(kProgram, unknown_command(all[1]).what(),
                                       insitu::cli::kExitBadInput);
        }
        insitu::cli::write_help(std::cout, command->help());
        return 0;
    }
    const Command* command = find_command(all[0]);
    if (!command) {
        return insitu::cli::report(kProgram, unknown_command(all[0]).what(),
                                   insitu::cli::kExitBadInput);
    }
    const std::vector<std::string> args(all.begin() + 1, all.end());
    return insitu::cli::run_command(kProgram, args, command->help(),
                                    [&] { return command->run(args); });
}
