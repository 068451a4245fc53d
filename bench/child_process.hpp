#pragma once
// Runs this benchmark again as a child process and reads back the figures it prints, for the
// measurements that need a process of their own: peak memory (bench_capture) or a CPU mask set
// before any thread starts (bench_overhead). The child prints one "key value" line per figure.
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace insitu::bench {

/// Figures a child printed: key -> the rest of its line.
using ChildFigures = std::map<std::string, std::string>;

/// Executes /proc/self/exe with `arguments` (argv[0] included), pinned to `cpu` when cpu >= 0
/// (the mask is set in the child before exec, so every thread it starts inherits it), and
/// returns its "key value" lines. Throws std::runtime_error naming `what` when the child cannot
/// be started or does not exit with 0.
inline ChildFigures run_self_as_child(const std::vector<std::string>& arguments,
                                      const std::string& what, int cpu = -1) {
    std::fflush(stdout);  // or the child inherits and prints our buffered output again
    int pipe_ends[2];
    if (pipe(pipe_ends) != 0) throw std::runtime_error(what + ": pipe failed");
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error(what + ": fork failed");
    if (pid == 0) {
        dup2(pipe_ends[1], STDOUT_FILENO);
        close(pipe_ends[0]);
        close(pipe_ends[1]);
        if (cpu >= 0) {
            cpu_set_t set;
            CPU_ZERO(&set);
            CPU_SET(cpu, &set);
            if (sched_setaffinity(0, sizeof(set), &set) != 0) {
                std::perror("sched_setaffinity");
                _exit(127);
            }
        }
        std::vector<char*> argv;
        for (const std::string& argument : arguments) {
            argv.push_back(const_cast<char*>(argument.c_str()));
        }
        argv.push_back(nullptr);
        execv("/proc/self/exe", argv.data());
        std::perror("execv");
        _exit(127);
    }
    close(pipe_ends[1]);
    std::string output;
    char buffer[4096];
    for (ssize_t got; (got = read(pipe_ends[0], buffer, sizeof(buffer))) > 0;) {
        output.append(buffer, static_cast<std::size_t>(got));
    }
    close(pipe_ends[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        throw std::runtime_error(what + " failed (wait status " + std::to_string(status) + ")");
    }
    ChildFigures figures;
    std::istringstream lines(output);
    for (std::string line; std::getline(lines, line);) {
        const auto space = line.find(' ');
        if (space != std::string::npos) figures[line.substr(0, space)] = line.substr(space + 1);
    }
    return figures;
}

}  // namespace insitu::bench
