#pragma once
// Newest-wins scheduling of the server's renders (viewer/server.hpp "Coalescing").
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <utility>

namespace insitu::viewer {

/// Newest-wins scheduling of renders: one render at a time, and per session at most one request
/// waiting; a waiting request that its session's newer request supersedes leaves at once.
class FrameScheduler {
public:
    /// Runs `job` once the engine is free, unless a newer request of `session` arrives first
    /// (then returns false without running it).
    template <typename Job>
    bool run(const std::string& session, Job&& job) {
        std::unique_lock<std::mutex> lock(mutex_);
        const std::uint64_t ticket = ++tickets_;
        latest_[session] = ticket;
        changed_.notify_all();
        const auto superseded = [&] {
            const auto found = latest_.find(session);
            return found == latest_.end() || found->second != ticket;
        };
        ++waiting_;
        changed_.wait(lock, [&] { return !busy_ || superseded(); });
        --waiting_;
        if (superseded()) return false;
        busy_ = true;
        lock.unlock();
        const auto finish = [&] {
            lock.lock();
            busy_ = false;
            if (!superseded()) latest_.erase(session);
            changed_.notify_all();
        };
        try {
            job();
        } catch (...) {
            finish();
            throw;
        }
        finish();
        return true;
    }

    /// Whether a render runs, and how many requests wait for the engine.
    std::pair<bool, int> load() {
        std::lock_guard<std::mutex> lock(mutex_);
        return {busy_, waiting_};
    }

private:
    std::mutex mutex_;
    std::condition_variable changed_;
    bool busy_ = false;
    int waiting_ = 0;
    std::uint64_t tickets_ = 0;
    /// Newest ticket per session with a request in flight (erased when it completes), so the
    /// map holds at most the sessions currently waiting or rendering.
    std::map<std::string, std::uint64_t> latest_;
};

}  // namespace insitu::viewer
