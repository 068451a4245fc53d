// Several runs as one gallery (static_site.hpp export_gallery): each run's site in a folder of
// its own and an index page of plain HTML (no script: any browser, any host) with a thumbnail,
// the steps and the size of each run, linking its explorer.
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "insitu/error.hpp"
#include "static_site.hpp"

namespace insitu::viewer {
namespace {

namespace fs = std::filesystem;

std::string escaped(const std::string& text) {
    std::string out;
    for (const char c : text) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

std::string megabytes(std::uintmax_t bytes) {
    std::ostringstream text;
    text.setf(std::ios::fixed);
    text.precision(1);
    text << static_cast<double>(bytes) / 1e6 << " MB";
    return text.str();
}

struct Run {
    std::string name;
    ExportReport report;
};

std::string index_html(const std::vector<Run>& runs) {
    std::ostringstream html;
    html << "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         << "<title>libinsitu gallery</title>\n<style>\n"
         << "body{font-family:sans-serif;margin:2em;background:#fafafa;color:#222}\n"
         << ".runs{display:flex;flex-wrap:wrap;gap:1.5em}\n"
         << ".run{background:#fff;border:1px solid "
            "#ccc;border-radius:6px;padding:.8em;width:260px}\n"
         << ".run img{width:256px;height:256px;object-fit:contain;background:#000}\n"
         << ".run h2{font-size:1.05em;margin:.4em 0}.run p{margin:.2em 0;font-size:.9em}\n"
         << "</style>\n</head>\n<body>\n<h1>Gallery</h1>\n"
         << "<p>Each run opens in the explorer: orbit, timesteps, opacity edits, lights, "
         << "confidence. Drawn in your browser (WebGL2) from the files here.</p>\n"
         << "<div class=\"runs\">\n";
    for (const Run& run : runs) {
        const std::string link = escaped(run.name) + "/index.html";
        html << "<div class=\"run\" data-run=\"" << escaped(run.name) << "\">\n<a href=\"" << link
             << "\"><img src=\"" << escaped(run.name) << "/" << escaped(run.report.thumbnail)
             << "\" alt=\"" << escaped(run.name) << "\"></a>\n<h2><a href=\"" << link << "\">"
             << escaped(run.name) << "</a></h2>\n<p>" << run.report.steps.size() << " step"
             << (run.report.steps.size() == 1 ? "" : "s") << " · <span class=\"size\">"
             << megabytes(run.report.bytes) << "</span></p>\n";
        for (const auto& [step, why] : run.report.left_out) {
            html << "<p class=\"left-out\">left out: step " << step << ": " << escaped(why)
                 << "</p>\n";
        }
        html << "</div>\n";
    }
    html << "</div>\n</body>\n</html>\n";
    return html.str();
}

nlohmann::json gallery_json(const std::vector<Run>& runs) {
    nlohmann::json list = nlohmann::json::array();
    for (const Run& run : runs) {
        nlohmann::json left_out = nlohmann::json::array();
        for (const auto& [step, why] : run.report.left_out) {
            left_out.push_back({{"step", step}, {"why", why}});
        }
        list.push_back({{"name", run.name},
                        {"steps", run.report.steps},
                        {"bytes", run.report.bytes},
                        {"thumbnail", run.name + "/" + run.report.thumbnail},
                        {"left_out", left_out}});
    }
    return {{"runs", list}};
}

}  // namespace

std::vector<ExportReport> export_gallery(const std::vector<std::string>& archives,
                                         const ExportOptions& options) {
    check_output(options);
    std::set<std::string> names;
    for (const std::string& archive : archives) {
        const std::string name = fs::absolute(archive).lexically_normal().filename().string();
        if (!names.insert(name).second) {
            fail<InvalidArgument>("two runs named \"", name, "\" (", archive,
                                  "): a gallery's runs need folders of different names");
        }
    }
    const fs::path out = fs::absolute(options.out).lexically_normal();
    const fs::path temporary = out.parent_path() / ("." + out.filename().string() + ".gallery");
    fs::remove_all(temporary);
    std::vector<Run> runs;
    try {
        for (const std::string& archive : archives) {
            ExportOptions run = options;
            run.archive = archive;
            run.replace = false;
            run.out = temporary / fs::absolute(archive).lexically_normal().filename();
            if (options.max_bytes) run.max_bytes = *options.max_bytes / archives.size();
            runs.push_back({run.out.filename().string(), export_site(run)});
        }
        std::ostringstream readme;
        readme << "A gallery of " << runs.size() << " runs, written by insitu-view export.\n\n"
               << "Host this folder on any static web server and open index.html through it,\n"
               << "e.g. python3 -m http.server 8000 --directory THIS_FOLDER. Each run's folder is\n"
               << "its explorer (its README.txt says more); gallery.json lists the runs.\n";
        write_files(temporary, {{"index.html", index_html(runs)},
                                {"gallery.json", gallery_json(runs).dump()},
                                {"README.txt", readme.str()}});
        if (fs::exists(out)) fs::remove_all(out);
        fs::rename(temporary, out);
    } catch (...) {
        fs::remove_all(temporary);
        throw;
    }
    std::vector<ExportReport> reports;
    for (Run& run : runs) reports.push_back(std::move(run.report));
    return reports;
}

}  // namespace insitu::viewer
