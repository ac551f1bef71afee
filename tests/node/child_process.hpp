// Runs one of the project's executables as a child process for tests: output (stdout and stderr)
// goes to a log file, and the test can wait for it, signal it, and read what it said.
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "temp_dir.hpp"

namespace vnsba::test {

// The executables under test, where this test target is given their paths.
#ifdef VNSBA_NODE_BINARY
inline const std::string kNode = VNSBA_NODE_BINARY;
#endif
#ifdef VNSBA_SLICER_BINARY
inline const std::string kSlicer = VNSBA_SLICER_BINARY;
#endif
#ifdef VNSBA_RECORDER_BINARY
inline const std::string kRecorder = VNSBA_RECORDER_BINARY;
#endif
#ifdef VNSBA_SEND_GOAL_BINARY
inline const std::string kSendGoal = VNSBA_SEND_GOAL_BINARY;
#endif

class ChildProcess {
 public:
  ChildProcess(const std::string& binary, const std::vector<std::string>& args) {
    log_ = (FreshTempDir("child") / "output.log").string();
    // Everything the child needs is made before fork(): the parent has DDS threads, one of which
    // may hold an allocator lock at the fork, and the child (this thread alone) would wait for
    // it forever: a child spun 4 minutes in AddressSanitizer's allocator, between freopen() and
    // execv(). Between fork and exec only async-signal-safe calls.
    std::vector<char*> argv{const_cast<char*>(binary.c_str())};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const int log_fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    pid_ = fork();
    if (pid_ == 0) {
      if (log_fd < 0 || dup2(log_fd, STDOUT_FILENO) < 0 || dup2(log_fd, STDERR_FILENO) < 0)
        _exit(127);
      execv(binary.c_str(), argv.data());
      _exit(127);
    }
    if (log_fd >= 0) ::close(log_fd);
  }
  ~ChildProcess() {
    if (running()) {
      kill(pid_, SIGKILL);
      wait();
    }
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  bool running() const { return pid_ > 0 && exit_code_ < 0; }
  pid_t pid() const { return pid_; }
  void signal(int sig) const { kill(pid_, sig); }

  // Waits for the exit; returns the exit code (128 + signal when killed by one). A child still
  // running after `deadline` (a hung shutdown) is killed with SIGKILL, which ends it even when
  // stopped: the wait ends and the test sees 128 + SIGKILL rather than hanging until ctest's
  // timeout.
  int wait(std::chrono::milliseconds deadline = std::chrono::seconds(120)) {
    if (exit_code_ >= 0) return exit_code_;
    int status = 0;
    const auto end = std::chrono::steady_clock::now() + deadline;
    pid_t done = waitpid(pid_, &status, WNOHANG);
    while (done == 0 && std::chrono::steady_clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      done = waitpid(pid_, &status, WNOHANG);
    }
    if (done == 0) {
      kill(pid_, SIGKILL);
      done = waitpid(pid_, &status, 0);
    }
    if (done != pid_) {  // not our child any more (reaped elsewhere): nothing to report
      exit_code_ = 127;
      return exit_code_;
    }
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return exit_code_;
  }

  // Polls the log until it contains `text` or `timeout` passes.
  bool wait_for_output(const std::string& text, std::chrono::milliseconds timeout) const {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      if (output().find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  std::string output() const {
    std::ifstream in(log_);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

 private:
  pid_t pid_ = -1;
  int exit_code_ = -1;
  std::string log_;
};

// Runs to completion and returns {exit code, output}; SIGTERM after `term_after` if non-zero.
inline std::pair<int, std::string> run_to_exit(
    const std::string& binary, const std::vector<std::string>& args,
    std::chrono::milliseconds term_after = std::chrono::milliseconds(0)) {
  ChildProcess child(binary, args);
  if (term_after.count() > 0) {
    std::this_thread::sleep_for(term_after);
    child.signal(SIGTERM);
  }
  const int code = child.wait();
  return {code, child.output()};
}

// `text` as `name` in a fresh directory of its own (FreshTempDir): nothing else is beside it.
inline std::string write_temp_file(const std::string& name, const std::string& text) {
  const std::string path = (FreshTempDir("file") / name).string();
  std::ofstream(path) << text;
  return path;
}

}  // namespace vnsba::test
