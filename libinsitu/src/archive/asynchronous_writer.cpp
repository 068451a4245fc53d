#include "archive/asynchronous_writer.hpp"

#include <string>

#include "archive/writer_thread.hpp"
#include "core/elapsed.hpp"

namespace insitu {

AsynchronousWriter::AsynchronousWriter(std::unique_ptr<ArchiveWriter> archive, int queue_limit,
                                       WhenFull when_full, RunStatistics& run)
    : archive_(std::move(archive)),
      queue_limit_(static_cast<std::size_t>(queue_limit)),
      when_full_(when_full),
      run_(run),
      worker_(&AsynchronousWriter::write_queued, this) {}

AsynchronousWriter::~AsynchronousWriter() {
    stop();
}

bool AsynchronousWriter::enqueue(StepRecord record, double compute_seconds) {
    run_.update([&](InstrumentStatistics& s) {
        ++s.steps_executed;
        s.compute_seconds += compute_seconds;
    });
    std::unique_lock<std::mutex> lock(mutex_);
    const auto full = [&] { return queue_.size() + writing_ >= queue_limit_; };
    if (full()) {
        if (when_full_ == WhenFull::drop) {
            run_.update([](InstrumentStatistics& s) { ++s.steps_dropped; });
            return false;
        }
        const auto start = SteadyClock::now();
        room_.wait(lock, [&] { return !full(); });
        const double blocked = seconds_since(start);
        run_.update([&](InstrumentStatistics& s) { s.blocked_seconds += blocked; });
    }
    queue_.push_back(std::move(record));
    work_ready_.notify_one();
    return true;
}

void AsynchronousWriter::stop() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
    }
    work_ready_.notify_all();
    if (worker_.joinable()) worker_.join();
}

void AsynchronousWriter::write_queued() {
    // Encoding and writing only when the simulation's core has nothing else to do (see
    // writer_thread.hpp); refused, the writer keeps the simulation's priority and loses nothing.
    archive_format::lower_writer_thread_priority();
    for (;;) {
        std::int64_t step = 0;
        std::uint64_t bytes = 0;
        std::string failure;
        std::exception_ptr failure_exception;
        double seconds = 0.0;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            work_ready_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
            if (queue_.empty()) return;  // stopping, and everything queued is written
            StepRecord record = std::move(queue_.front());
            queue_.pop_front();
            ++writing_;
            lock.unlock();

            step = record.step;
            const auto start = SteadyClock::now();
            try {
                bytes = archive_->write(record).bytes();
            } catch (const std::exception& error) {
                failure = error.what();
                failure_exception = std::current_exception();
            } catch (...) {
                failure = "unknown exception";
                failure_exception = std::current_exception();
            }
            seconds = seconds_since(start);
        }  // the record's images are freed here, before the queue reports room

        // Counted before the queue reports room: a simulation waiting for room finds the write's
        // outcome (a distributed run tells every rank of a failure at its next step).
        run_.update([&](InstrumentStatistics& s) {
            s.write_seconds += seconds;
            if (failure.empty()) {
                ++s.steps_written;
                s.bytes_written += bytes;
            }
        });
        if (!failure.empty()) {
            run_.record_write_failure("writing step " + std::to_string(step) + ": " + failure,
                                      classify(failure_exception), failure_exception);
        }
        {
            std::lock_guard<std::mutex> lock(mutex_);
            --writing_;
        }
        // After the unlock: the waiting simulation wakes and preempts this low-priority thread
        // at once, and must not then find the mutex still held by it.
        room_.notify_all();
    }
}

}  // namespace insitu
