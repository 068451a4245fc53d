#pragma once
// The "interleaving" proxy (ProxyFrame::interleaving) across the blocks of a distributed run.
// One pass counts a re-entry where a contributing sample falls in an interval other than the
// last one's that already holds light, and adds the light of such re-entered runs. A block
// counts from its own entry, as if nothing were in front, so it also records (its partial
// frame's interleaving, kInterleavingHead + L channels, kernels/render/proxy_renderer.cl):
//   0 re-entries and 1 their light (weights from T = 1 at the block's entry),
//   2 the interval of its first run and 3 of its last (-1: no light in the block),
//   4 whether its last run re-enters within the block (1) or is the block's first run of its
//     interval (0),
//   5 + j the light of the block's first run of interval j.
// Folded front to back, a block's first run of j re-enters where j holds light in front; its
// very first run continues the front's last run where both are of one interval (no re-entry,
// and re-entering as the front's last run was). Every later run of j re-entered within the
// block already. What the fold leaves is one pass's (count, light) up to float rounding of the
// light.
namespace insitu::detail {

struct InterleavingFold {
    double reentries = 0.0;
    double reentered = 0.0;
    int last_interval = -1;   ///< of the last contributing sample in front
    bool reentering = false;  ///< whether that sample's run re-entered its interval

    /// Starts from the front-most block's record: nothing is in front of it.
    void start(const float* record);
    /// Folds the record of the block behind what was folded so far: `front_attenuation` (L) is
    /// the a_j of everything in front of it, `transmittance` the T in front of it.
    void add(const float* record, int intervals, const float* front_attenuation,
             double transmittance);
};

}  // namespace insitu::detail
