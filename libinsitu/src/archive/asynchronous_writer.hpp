#pragma once
// The asynchronous writer (DESIGN.md data flow): an ArchiveWriter on a worker thread behind a
// bounded queue, so that execute() returns once a step's record is queued. The record being
// written counts against the queue too: "writer.queue" bounds the steps held in memory.
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>

#include "insitu/archive/archive_writer.hpp"
#include "insitu/archive/step_record.hpp"
#include "insitu/config.hpp"
#include "run_statistics.hpp"

namespace insitu {

class AsynchronousWriter {
public:
    /// Starts the worker thread; its writes and failures are counted in `run`, which must
    /// outlive the writer.
    AsynchronousWriter(std::unique_ptr<ArchiveWriter> archive, int queue_limit, WhenFull when_full,
                       RunStatistics& run);
    ~AsynchronousWriter();  ///< stop()s
    AsynchronousWriter(const AsynchronousWriter&) = delete;
    AsynchronousWriter& operator=(const AsynchronousWriter&) = delete;

    /// Queues a step's record, counting it executed. With the queue full: waits for room
    /// (WhenFull::block, timed in blocked_seconds) or drops it (counted) and returns false.
    bool enqueue(StepRecord record, double compute_seconds);
    /// Writes what is queued and joins the worker; later calls do nothing.
    void stop();

private:
    void write_queued();

    std::unique_ptr<ArchiveWriter> archive_;  ///< touched by the worker only
    const std::size_t queue_limit_;
    const WhenFull when_full_;
    RunStatistics& run_;

    std::mutex mutex_;
    std::condition_variable work_ready_;  ///< a record was queued, or stop
    std::condition_variable room_;        ///< a write finished: the queue has room
    std::deque<StepRecord> queue_;
    std::size_t writing_ = 0;  ///< records taken off the queue and still being written
    bool stopping_ = false;
    std::thread worker_;
};

}  // namespace insitu
