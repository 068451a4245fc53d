// Crash safety of the archive (DESIGN.md "Archive", issue 4): a child process appends steps to an
// archive as fast as it can and is SIGKILLed after a random delay, many times with different
// seeds. Each time the archive must open, hold every step the child finished (and at most the
// one it was finishing when it died: write() may have returned without the child getting to say
// so), load every one of them, pass verify(), and take further steps from a new writer.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "insitu/archive/archive.hpp"
#include "insitu/error.hpp"

namespace insitu {
namespace {

constexpr int kRuns = 30;
// Delays span opening the archive (a few ms) to several steps written (each step fsyncs four
// files, their folders and two index appends); the whole test stays well under 20 s.
constexpr int kMinDelayMs = 1;
constexpr int kMaxDelayMs = 40;
constexpr int kImageSize = 16;

StepRecord small_step(std::int64_t step) {
    StepRecord record;
    record.step = step;
    record.time = 0.5 * step;
    record.field = "v";
    ViewRecord view;
    view.view.orbit.width = view.view.orbit.height = kImageSize;
    ProxyFrame frame;
    frame.camera = Camera::orbit(view.view.orbit, Bounds{{0, 0, 0}, {1, 1, 1}});
    frame.isovalues = {0.5};
    frame.intervals = IntervalSet::uniform(0.0, 1.0, 4);
    frame.depth_layers = {Image(kImageSize, kImageSize, 1, 0.25f * step)};
    frame.attenuation = Image(kImageSize, kImageSize, 4, 0.125f);
    frame.mean_depth = Image(kImageSize, kImageSize, 4, 1.0f);
    view.single = frame;
    view.preview = Image(kImageSize, kImageSize, 4, 0.5f);
    record.views.push_back(view);
    record.views.push_back(view);
    record.views.back().view_index = 1;
    return record;
}

// The child: appends steps from `first` on, reporting each finished step on `report`, until it
// is killed. It never returns.
[[noreturn]] void write_until_killed(const InstrumentConfig& config, std::int64_t first,
                                     int report) {
    try {
        ArchiveWriter writer(config);
        for (std::int64_t step = first;; ++step) {
            writer.write(small_step(step));
            if (::write(report, &step, sizeof step) != sizeof step) ::_exit(3);
        }
    } catch (const std::exception& error) {
        std::fprintf(stderr, "child: %s\n", error.what());
        ::_exit(2);
    }
}

TEST(ArchiveCrash, KilledWriterLeavesAnArchiveWithEveryCompletedStep) {
    const std::filesystem::path directory = std::filesystem::temp_directory_path() /
                                            ("insitu_archive_crash_" + std::to_string(::getpid()));
    std::filesystem::remove_all(directory);
    InstrumentConfig config;
    config.every = 1;  // every step is emitted (the default is every 10th)
    config.archive = (directory / "run.cdb").string();
    config.precision = StoragePrecision::half;

    // The archive exists before the first kill, so that every run must find it openable.
    ArchiveWriter(config).write(small_step(0));
    std::int64_t next_step = 1;

    for (int run = 0; run < kRuns; ++run) {
        SCOPED_TRACE("run " + std::to_string(run));
        std::mt19937 random(static_cast<unsigned>(run) * 7919u + 17u);
        const int delay_ms = std::uniform_int_distribution<int>(kMinDelayMs, kMaxDelayMs)(random);

        int pipe_fds[2];
        ASSERT_EQ(::pipe(pipe_fds), 0);
        const pid_t child = ::fork();
        ASSERT_GE(child, 0);
        if (child == 0) {
            ::close(pipe_fds[0]);
            write_until_killed(config, next_step, pipe_fds[1]);
        }
        ::close(pipe_fds[1]);
        std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
        ::kill(child, SIGKILL);
        int status = 0;
        ASSERT_EQ(::waitpid(child, &status, 0), child);
        ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
            << "the child ended by itself (status " << status << ") before the kill";

        std::vector<std::int64_t> reported;
        std::int64_t step = 0;
        while (::read(pipe_fds[0], &step, sizeof step) == sizeof step) reported.push_back(step);
        ::close(pipe_fds[0]);

        const ArchiveReader reader(config.archive);
        const std::vector<std::int64_t> steps = reader.steps();
        const std::int64_t finished = next_step + static_cast<std::int64_t>(reported.size());
        // Steps 0..finished-1 all present; at most one more, nothing else.
        ASSERT_GE(static_cast<std::int64_t>(steps.size()), finished);
        ASSERT_LE(static_cast<std::int64_t>(steps.size()), finished + 1);
        for (std::size_t i = 0; i < steps.size(); ++i) {
            ASSERT_EQ(steps[i], static_cast<std::int64_t>(i));
        }
        for (const std::int64_t archived : steps) {
            for (int view = 0; view < 2; ++view) {
                const ProxyFrame frame = reader.load(archived, view);
                ASSERT_EQ(frame.depth_layers.size(), 1u);
                ASSERT_EQ(frame.depth_layers[0].pixels[0], 0.25f * archived);
                ASSERT_EQ(reader.load_preview(archived, view).width, kImageSize);
            }
        }
        const std::vector<std::string> problems = reader.verify();
        ASSERT_TRUE(problems.empty()) << problems.front();
        next_step = static_cast<std::int64_t>(steps.size());
    }

    // After all that, a new writer continues and its temp-file leftovers are gone.
    ArchiveWriter writer(config);
    writer.write(small_step(next_step));
    for (const auto& folder : {directory / "run.cdb", directory / "run.cdb" / "proxies",
                               directory / "run.cdb" / "previews"}) {
        for (const auto& entry : std::filesystem::directory_iterator(folder)) {
            EXPECT_NE(entry.path().filename().string().rfind(".tmp-", 0), 0u) << entry.path();
        }
    }
    EXPECT_EQ(ArchiveReader(config.archive).steps().size(),
              static_cast<std::size_t>(next_step + 1));
    std::filesystem::remove_all(directory);
}

// One writer at a time (issue 19): a child process holds the archive's lock; a writer here is
// refused naming the child's pid; once the child is SIGKILLed the kernel has dropped its lock and
// a new writer succeeds, with every step the child wrote.
TEST(ArchiveCrash, LockOfAKilledWriterIsReleased) {
    const std::filesystem::path directory = std::filesystem::temp_directory_path() /
                                            ("insitu_archive_lock_" + std::to_string(::getpid()));
    std::filesystem::remove_all(directory);
    InstrumentConfig config;
    config.every = 1;  // every step is emitted (the default is every 10th)
    config.archive = (directory / "run.cdb").string();

    int pipe_fds[2];
    ASSERT_EQ(::pipe(pipe_fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        ::close(pipe_fds[0]);
        try {
            ArchiveWriter writer(config);
            writer.write(small_step(0));
            const std::int64_t ready = 0;
            if (::write(pipe_fds[1], &ready, sizeof ready) != sizeof ready) ::_exit(3);
            for (;;) ::pause();
        } catch (const std::exception& error) {
            std::fprintf(stderr, "child: %s\n", error.what());
            ::_exit(2);
        }
    }
    ::close(pipe_fds[1]);
    std::int64_t ready = -1;
    ASSERT_EQ(::read(pipe_fds[0], &ready, sizeof ready), static_cast<ssize_t>(sizeof ready));
    ::close(pipe_fds[0]);
    try {
        ArchiveWriter second(config);
        ADD_FAILURE() << "a second writer was let in";
    } catch (const IoError& error) {
        EXPECT_NE(std::string(error.what()).find("pid " + std::to_string(child)), std::string::npos)
            << error.what();
        EXPECT_NE(std::string(error.what()).find(config.archive), std::string::npos)
            << error.what();
    }
    ::kill(child, SIGKILL);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);

    ArchiveWriter writer(config);
    writer.write(small_step(1));
    EXPECT_EQ(ArchiveReader(config.archive).steps(), (std::vector<std::int64_t>{0, 1}));
    std::filesystem::remove_all(directory);
}

}  // namespace
}  // namespace insitu
