// Scratch directories for the tests. Every call of FreshTempDir makes a new, empty directory of
// its own under ::testing::TempDir() (TMPDIR, else /tmp), with mkdtemp, so no two calls, tests or
// processes ever share one and nothing a test reads can be a leftover of another test or of an
// earlier run (issue 45: a test passed only where an older run had left its file behind). The
// process removes every directory it made when it exits, whether its tests passed or failed.
//
// This is the only file under tests/ that may name the system's temp directory: the test
// TestTree.NoTestNamesATempPathOfItsOwn (tests/hygiene/test_temp_paths.cpp) fails on any other.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace vnsba::test {

namespace temp_dir_detail {

// The directories this process made, removed when it exits. Each one is kept with the process
// that made it: a child forked by a test (ChildProcess, a death test) that exits normally runs
// this destructor too, and must not remove its parent's directories.
class Made {
 public:
  static Made& instance() {
    static Made made;
    return made;
  }
  void add(const std::filesystem::path& dir) {
    std::lock_guard<std::mutex> lock(mutex_);
    dirs_.emplace_back(::getpid(), dir);
  }
  ~Made() {
    const pid_t self = ::getpid();
    for (const auto& [pid, dir] : dirs_) {
      if (pid != self) continue;
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
      // Said, not hidden: a directory left behind would fill TMPDIR run after run.
      if (ec) std::cerr << "could not remove " << dir.string() << ": " << ec.message() << "\n";
    }
  }

 private:
  Made() = default;
  std::mutex mutex_;
  std::vector<std::pair<pid_t, std::filesystem::path>> dirs_;
};

}  // namespace temp_dir_detail

// A new, empty directory, absolute (a test may change the working directory), named
// vnsba_<label>_XXXXXX under ::testing::TempDir(); `label` only helps a reader find it (characters
// other than letters, digits, '.', '-' and '_' become '_'). Throws std::runtime_error, which
// fails the calling test, when it cannot be made (TMPDIR missing or not writable).
inline std::filesystem::path FreshTempDir(const std::string& label) {
  std::string name = "vnsba_";
  for (const char c : label.substr(0, 64)) {  // a test name can be long; a file name cannot
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '-' || c == '_';
    name += keep ? c : '_';
  }
  const std::filesystem::path base = std::filesystem::absolute(::testing::TempDir());
  std::string pattern = (base / (name + "_XXXXXX")).lexically_normal().string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    const int error = errno;
    throw std::runtime_error("cannot make a directory " + pattern + " (::testing::TempDir() is " +
                             ::testing::TempDir() + "): " + std::strerror(error));
  }
  const std::filesystem::path dir(pattern);
  temp_dir_detail::Made::instance().add(dir);
  return dir;
}

}  // namespace vnsba::test
