#include "representation/volume/volume_representation.hpp"

#include <algorithm>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/elapsed.hpp"
#include "insitu/budget/volume_chooser.hpp"
#include "insitu/explore/transfer_function_edit.hpp"
#include "insitu/render/volume_renderer.hpp"
#include "representation/volume/volume_entries.hpp"
#include "representation/volume/volume_frames.hpp"
#include "representation/volume/zfp_volume.hpp"

namespace insitu {

namespace {

double value_range(const FieldPlan& plan) {
    return plan.summary.histogram.max - plan.summary.histogram.min;
}

/// A tolerance measured as a reader gets the field back: compressed as the writer compresses
/// it, decoded, and rendered by the ground truth in the budget's views, with the held-out edit
/// and with the sharp held-out function (a compressed field's error shows most where a function
/// is steep), against those functions' truths on the original field.
class VolumeCandidates {
public:
    explicit VolumeCandidates(const FieldBudgetCheck& check)
        : check_(check),
          sharp_(sharp_held_out(check.plan.transfer_function, check.plan.summary.histogram.min,
                                check.plan.summary.histogram.max)) {
        for (const BudgetView& view : check.views) {
            sharp_truths_.push_back(
                check.renderer.render_ground_truth(view.camera, sharp_, check.truth_settings).rgba);
        }
    }

    BudgetRecord::VolumeChoice measure(double relative_tolerance) {
        const DeviceVolume& field = check_.renderer.volume();
        VolumeSettings settings;
        settings.relative_tolerance = relative_tolerance;
        const archive_format::ZfpParameters parameters{
            VolumeMode::accuracy, settings.tolerance_for(value_range(check_.plan)), 0.0,
            check_.config.volume ? check_.config.volume->threads : 1};
        BudgetRecord::VolumeChoice candidate;
        candidate.relative_tolerance = relative_tolerance;
        const auto start = SteadyClock::now();
        const archive_format::EncodedVolumeBlock encoded =
            archive_format::encode_volume_block(field.host_values.data(), field.dims, parameters);
        candidate.milliseconds = milliseconds_since(start);
        candidate.bytes = static_cast<double>(encoded.stream.size() + encoded.mask.size());
        const std::vector<float> decoded =
            archive_format::decode_volume_block({encoded.stream.begin(), encoded.stream.end()},
                                                {encoded.mask.begin(), encoded.mask.end()},
                                                field.dims, encoded.nonfinite, "budget check");
        Field view(check_.plan.name, decoded.data(), ScalarType::float32, field.dims);
        view.set_origin(field.origin).set_spacing(field.spacing);
        decoded_.upload(view);
        candidate.psnr_db = std::numeric_limits<double>::infinity();
        for (std::size_t v = 0; v < check_.views.size(); ++v) {
            const BudgetView& target = check_.views[v];
            const Image held_out =
                decoded_.render(target.camera, check_.held_out, check_.truth_settings).rgba;
            const Image sharp = decoded_.render(target.camera, sharp_, check_.truth_settings).rgba;
            candidate.psnr_db = std::min({candidate.psnr_db, psnr_rgb_db(target.truth, held_out),
                                          psnr_rgb_db(sharp_truths_[v], sharp)});
        }
        return candidate;
    }

private:
    const FieldBudgetCheck& check_;
    TransferFunction sharp_;
    std::vector<Image> sharp_truths_;
    VolumeRenderer decoded_;
};

/// The smallest distance between two control points of `tf` that differ: how narrow a feature
/// of the field it shows (infinite for a constant function).
double narrowest_feature(const TransferFunction& tf) {
    double narrowest = std::numeric_limits<double>::infinity();
    for (const TransferRow& row : tf.rows()) {
        for (std::size_t i = 1; i < row.points.size(); ++i) {
            if (row.points[i].rgba != row.points[i - 1].rgba) {
                narrowest = std::min(narrowest, row.points[i].value - row.points[i - 1].value);
            }
        }
    }
    return narrowest;
}

/// What this step keeps the field with, or none: the budget's choice where it chose whether to
/// (at its tolerance), else the configuration's "volume", else the default rule
/// (volume_settings.hpp).
std::optional<VolumeSettings> kept_settings(const InstrumentConfig& config, const FieldPlan& plan) {
    if (plan.budget && plan.budget->volume) {
        if (!plan.budget->volume->met) return std::nullopt;
        VolumeSettings chosen = config.volume.value_or(VolumeSettings{});
        chosen.mode = VolumeMode::accuracy;
        chosen.tolerance.reset();
        chosen.rate.reset();
        chosen.relative_tolerance = plan.budget->volume->relative_tolerance;
        return chosen;
    }
    if (config.volume) return config.volume;
    // By default where the whole grid is small enough to keep (the same rule for one process and
    // a distributed run, which the Instrument turns off where a rank cannot reach the archive).
    const Index3& grid = plan.placement.grid_dims;
    const bool by_default = !config.no_volume && !config.budget &&
                            static_cast<double>(grid[0]) * static_cast<double>(grid[1]) *
                                    static_cast<double>(grid[2]) <=
                                static_cast<double>(kDefaultVolumeMaxSamples);
    return by_default ? std::optional<VolumeSettings>(VolumeSettings{}) : std::nullopt;
}

/// The interior of a rank's uploaded block (its first `interior` samples per axis; the marched
/// ghost layers lie beyond them), x fastest.
std::vector<float> interior_values(const DeviceVolume& uploaded, const Index3& interior) {
    std::vector<float> values;
    values.reserve(static_cast<std::size_t>(interior[0] * interior[1] * interior[2]));
    for (std::int64_t z = 0; z < interior[2]; ++z) {
        for (std::int64_t y = 0; y < interior[1]; ++y) {
            const auto row =
                uploaded.host_values.begin() +
                static_cast<std::ptrdiff_t>(uploaded.dims[0] * (y + uploaded.dims[1] * z));
            values.insert(values.end(), row, row + interior[0]);
        }
    }
    return values;
}

nlohmann::json placed_json(const BlockPlacement& where, const VolumeRecord::Block::Placed& placed) {
    nlohmann::json files = nlohmann::json::array();
    for (const WrittenFile& file : placed.files) {
        files.push_back({file.relative_path, file.bytes, file.crc32});
    }
    return {{"offset", where.offset},
            {"dims", where.dims},
            {"nonfinite", placed.nonfinite},
            {"files", std::move(files)}};
}

VolumeRecord::Block block_from_json(const nlohmann::json& said) {
    VolumeRecord::Block block;
    block.offset = said.at("offset").get<Index3>();
    block.dims = said.at("dims").get<Index3>();
    VolumeRecord::Block::Placed placed;
    placed.nonfinite = said.at("nonfinite").get<std::int64_t>();
    for (const nlohmann::json& file : said.at("files")) {
        placed.files.push_back({file.at(0).get<std::string>(), file.at(1).get<std::uint64_t>(),
                                file.at(2).get<std::uint32_t>()});
    }
    block.placed = std::move(placed);
    return block;
}

/// A distributed run's blocks: each rank compresses its own interior and places its files
/// (crash-safely, before it answers), then rank 0 learns what every rank placed. Nothing of
/// the field itself crosses ranks; rank 0 indexes the step only after every block is durable.
std::vector<VolumeRecord::Block> placed_blocks(const InstrumentConfig& config,
                                               const FieldPlan& plan, const VolumeRecord& volume,
                                               std::int64_t step, StepPasses& passes) {
    Bytes said;
    passes.guard([&] {
        if (!plan.has_block) return;
        const BlockPlacement& where = plan.placement;
        const auto field = std::find(config.fields.begin(), config.fields.end(), plan.name);
        const archive_format::VolumeBlockName name{
            step, static_cast<int>(field - config.fields.begin()), where.index, where.count};
        const std::vector<float> values = interior_values(passes.renderer().volume(), where.dims);
        const VolumeRecord::Block::Placed placed = archive_format::place_volume_block(
            config.archive, name, values.data(), where.dims,
            {volume.mode, volume.tolerance, volume.rate, volume.threads});
        const std::string text = placed_json(where, placed).dump();
        said.assign(text.begin(), text.end());
    });
    std::vector<VolumeRecord::Block> blocks;
    for (const Bytes& bytes : passes.gather(said)) {
        if (bytes.empty()) continue;  // a rank that owns nothing of the field
        blocks.push_back(block_from_json(nlohmann::json::parse(bytes.begin(), bytes.end())));
    }
    return blocks;
}

}  // namespace

void VolumeRepresentation::capture(const InstrumentConfig& config, const FieldPlan& plan,
                                   const FieldRecipe&, StepPasses& passes,
                                   StepRecord& record) const {
    const std::optional<VolumeSettings> settings = kept_settings(config, plan);
    if (!settings) return;
    double narrowest = narrowest_feature(plan.transfer_function);
    for (const TransferFunction& training : config.training_transfer_functions) {
        narrowest = std::min(narrowest, narrowest_feature(training));
    }
    VolumeRecord volume;
    volume.field = plan.name;
    volume.dims = plan.placement.grid_dims;
    volume.origin = plan.placement.origin;
    volume.spacing = plan.placement.spacing;
    volume.mode = settings->mode;
    volume.min = plan.summary.histogram.min;
    volume.max = plan.summary.histogram.max;
    volume.tolerance = settings->tolerance_for(value_range(plan), narrowest);
    volume.rate = settings->rate.value_or(0.0);
    volume.threads = settings->threads;
    if (passes.holds_whole_field()) {
        // The uploaded copy is already the interior as float, NaN where the field is
        // non-finite; the writer compresses it on its thread.
        const DeviceVolume& uploaded = passes.renderer().volume();
        volume.blocks.push_back({{0, 0, 0}, uploaded.dims, uploaded.host_values});
    } else {
        volume.blocks = placed_blocks(config, plan, volume, record.step, passes);
    }
    if (passes.holds_results()) record.volumes.push_back(std::move(volume));
}

void VolumeRepresentation::choose(const FieldBudgetCheck& check, BudgetRecord& choice) const {
    // "volume": false keeps none, whatever the budget may choose.
    if (!check.budget.chooses_volume || check.config.no_volume) return;
    VolumeCandidates candidates(check);
    choice.volume = choose_volume(check.share_after(choice), [&](double relative_tolerance) {
        return candidates.measure(relative_tolerance);
    });
}

std::unique_ptr<detail::FrameMaker> VolumeRepresentation::frame_maker(
    std::shared_ptr<ComputeDevice> device) const {
    return std::make_unique<detail::VolumeFrameMaker>(std::move(device));
}

}  // namespace insitu
