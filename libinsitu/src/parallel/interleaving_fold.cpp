#include "parallel/interleaving_fold.hpp"

#include "device/kernel_constants.hpp"

namespace insitu::detail {

namespace {

// The record's head, as the header lists it.
enum InterleavingChannel { kReentries, kReentered, kFirstRun, kLastRun, kLastRunReenters };
static_assert(kLastRunReenters + 1 == kInterleavingHead, "the head's channels");

}  // namespace

void InterleavingFold::start(const float* record) {
    reentries = record[kReentries];
    reentered = record[kReentered];
    last_interval = static_cast<int>(record[kLastRun]);
    reentering = record[kLastRunReenters] != 0.0f;
}

void InterleavingFold::add(const float* record, int intervals, const float* front_attenuation,
                           double transmittance) {
    const int first = static_cast<int>(record[kFirstRun]);
    if (first < 0 || first >= intervals) return;  // no light in the block
    const int last = static_cast<int>(record[kLastRun]);
    const bool continues = first == last_interval;
    double count = record[kReentries];
    double light = record[kReentered];
    const float* first_runs = record + kInterleavingHead;
    for (int j = 0; j < intervals; ++j) {
        if (!(first_runs[j] > 0.0f)) continue;
        if (j == first && continues) {
            if (reentering) light += first_runs[j];  // the front's run goes on
        } else if (front_attenuation[j] > 0.0f) {
            count += 1.0;
            light += first_runs[j];
        }
    }
    bool last_reenters = record[kLastRunReenters] != 0.0f;
    if (!last_reenters && last >= 0 && last < intervals) {
        // The block's first run of that interval: the only run where it is also the first.
        last_reenters = last == first && continues ? reentering : front_attenuation[last] > 0.0f;
    }
    reentries += count;
    reentered += transmittance * light;
    last_interval = last;
    reentering = last_reenters;
}

}  // namespace insitu::detail
