// .vti and .pvd inputs (VTK). VTK reports read errors through vtkOutputWindow (several lines on
// stderr, and the read "succeeds" with an empty or partial data set); a reader here routes that
// window into a string for the duration of the read and turns any error into one IoError naming
// the file. The window and vtkLogger's verbosity are process-wide: a read must not run
// concurrently with other VTK work that expects its messages on stderr.
#include <vtkImageData.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLUtilities.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "capture_readers.hpp"
#include "insitu/error.hpp"
#include "insitu/vtk_adaptor.hpp"

namespace insitu::capture::detail {

namespace {

/// Collects what VTK would print.
class CollectingOutputWindow : public vtkOutputWindow {
public:
    static CollectingOutputWindow* New();

    void DisplayText(const char* text) override { collect(text, false); }
    void DisplayErrorText(const char* text) override { collect(text, true); }
    void DisplayWarningText(const char* text) override { collect(text, false); }
    void DisplayGenericWarningText(const char* text) override { collect(text, false); }
    void DisplayDebugText(const char*) override {}

    /// The first error, without VTK's "ERROR: In file, line N" and "vtkClass (0x...): " prefixes.
    const std::string& first_error() const { return first_error_; }

private:
    void collect(const char* text, bool is_error) {
        if (!is_error || !first_error_.empty() || !text) return;
        std::istringstream lines(text);
        std::string line;
        std::string message;
        while (std::getline(lines, line)) {
            if (line.empty() || line.rfind("ERROR: In ", 0) == 0) continue;
            if (const auto prefix = line.find("): ");
                line.rfind("vtk", 0) == 0 && prefix != line.npos) {
                line = line.substr(prefix + 3);
            }
            message += (message.empty() ? "" : " ") + line;
        }
        first_error_ = message.empty() ? std::string("unknown VTK error") : message;
    }

    std::string first_error_;
};

vtkStandardNewMacro(CollectingOutputWindow);

/// Installs a CollectingOutputWindow and silences vtkLogger's stderr copy of each error while it
/// lives, then puts both back.
class ScopedOutputCapture {
public:
    ScopedOutputCapture()
        : previous_(vtkOutputWindow::GetInstance()),
          previous_verbosity_(vtkLogger::GetCurrentVerbosityCutoff()) {
        vtkOutputWindow::SetInstance(window_);
        vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    }
    ~ScopedOutputCapture() {
        vtkLogger::SetStderrVerbosity(previous_verbosity_);
        vtkOutputWindow::SetInstance(previous_);
    }
    ScopedOutputCapture(const ScopedOutputCapture&) = delete;
    ScopedOutputCapture& operator=(const ScopedOutputCapture&) = delete;

    const std::string& first_error() const { return window_->first_error(); }

private:
    vtkSmartPointer<vtkOutputWindow> previous_;
    vtkLogger::Verbosity previous_verbosity_;
    vtkNew<CollectingOutputWindow> window_;
};

class VtiStep : public LoadedStep {
public:
    VtiStep(std::string path, vtkSmartPointer<vtkImageData> image, vtk::VtkField field)
        : path_(std::move(path)), image_(std::move(image)), field_(std::move(field)) {}
    Field field() const override { return field_.field(); }
    std::string describe() const override {
        const Index3 dims = field_.field().dims();
        std::ostringstream text;
        text << "vti " << vtk::to_string(field_.association()) << " data \""
             << field_.field().name() << "\" " << dims[0] << "x" << dims[1] << "x" << dims[2]
             << (field_.copied() ? " (copied: " + field_.copy_reason() + ")" : "");
        return text.str();
    }

private:
    std::string path_;
    vtkSmartPointer<vtkImageData> image_;
    vtk::VtkField field_;
};

}  // namespace

std::unique_ptr<LoadedStep> load_vti(const std::string& path, const InputOptions& options) {
    if (!std::filesystem::is_regular_file(path)) {
        fail<IoError>("\"", path, "\": no such file");
    }
    ScopedOutputCapture capture;
    vtkNew<vtkXMLImageDataReader> reader;
    if (!reader->CanReadFile(path.c_str())) {
        fail<IoError>("\"", path, "\": not a VTK XML image data (.vti) file");
    }
    reader->SetFileName(path.c_str());
    reader->Update();
    if (!capture.first_error().empty()) {
        fail<IoError>("\"", path, "\": VTK could not read it: ", capture.first_error());
    }
    vtkSmartPointer<vtkImageData> image = reader->GetOutput();
    vtk::ArraySelection selection;
    selection.name = options.array_name;
    try {
        vtk::VtkField field = vtk::to_field(*image, selection, options.field_name);
        return std::make_unique<VtiStep>(path, image, std::move(field));
    } catch (const InvalidArgument& error) {
        fail<InvalidArgument>("\"", path, "\": ", error.what());
    }
}

std::vector<InputStep> read_pvd(const std::string& path) {
    if (!std::filesystem::is_regular_file(path)) fail<IoError>("\"", path, "\": no such file");
    ScopedOutputCapture capture;
    vtkSmartPointer<vtkXMLDataElement> root;
    root.TakeReference(vtkXMLUtilities::ReadElementFromFile(path.c_str()));
    if (!root || !capture.first_error().empty()) {
        fail<ParseError>(
            "\"", path, "\": not an XML file (",
            capture.first_error().empty() ? std::string("empty") : capture.first_error(), ")");
    }
    const char* type = root->GetAttribute("type");
    vtkXMLDataElement* collection = root->FindNestedElementWithName("Collection");
    if (std::string(root->GetName()) != "VTKFile" || !type || std::string(type) != "Collection" ||
        !collection) {
        fail<ParseError>("\"", path,
                         "\": not a ParaView collection (<VTKFile type=\"Collection\"> with a "
                         "<Collection> element)");
    }
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    std::vector<InputStep> steps;
    for (int n = 0; n < collection->GetNumberOfNestedElements(); ++n) {
        vtkXMLDataElement* data_set = collection->GetNestedElement(n);
        if (std::string(data_set->GetName()) != "DataSet") continue;
        const char* file = data_set->GetAttribute("file");
        if (!file) fail<ParseError>("\"", path, "\": DataSet ", n, " has no \"file\" attribute");
        if (const char* part = data_set->GetAttribute("part"); part && std::string(part) != "0") {
            fail<ParseError>("\"", path, "\": DataSet \"", file, "\" is part ", part,
                             "; multi-part collections are not supported");
        }
        double time = static_cast<double>(steps.size());
        if (data_set->GetAttribute("timestep") && !data_set->GetScalarAttribute("timestep", time)) {
            fail<ParseError>("\"", path, "\": DataSet \"", file, "\" has timestep \"",
                             data_set->GetAttribute("timestep"), "\", not a number");
        }
        InputStep step;
        step.path = (folder / file).string();
        step.kind = input_kind(step.path);
        if (step.kind != InputKind::vti) {
            fail<ParseError>("\"", path, "\": DataSet \"", file,
                             "\" is not a .vti file (only image data collections are supported)");
        }
        step.time = time;
        steps.push_back(std::move(step));
    }
    if (steps.empty()) fail<ParseError>("\"", path, "\": the collection lists no DataSet");
    std::stable_sort(steps.begin(), steps.end(),
                     [](const InputStep& a, const InputStep& b) { return *a.time < *b.time; });
    return steps;
}

}  // namespace insitu::capture::detail
