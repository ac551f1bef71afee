// What the process logs through spdlog while a LogCapture lives: a sink added to the default
// logger (the node's, and every tool's in this process). Make it before starting anything that
// logs and let it go after stopping that: spdlog's sink list is not safe to change while another
// thread logs.
#pragma once

#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace vnsba::test {

class LogCapture {
 public:
  LogCapture() : sink_(std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(kLines)) {
    sink_->set_pattern("[%l] %v");
    spdlog::default_logger()->sinks().push_back(sink_);
  }
  ~LogCapture() {
    auto& sinks = spdlog::default_logger()->sinks();
    sinks.erase(std::remove(sinks.begin(), sinks.end(), sink_), sinks.end());
  }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;

  // The lines logged so far (the last kLines), as "[level] message".
  std::vector<std::string> lines() const { return sink_->last_formatted(); }

  // The lines that contain every one of `parts`.
  std::vector<std::string> matching(const std::vector<std::string>& parts) const {
    std::vector<std::string> out;
    for (const std::string& line : lines()) {
      if (std::all_of(parts.begin(), parts.end(), [&](const std::string& part) {
            return line.find(part) != std::string::npos;
          }))
        out.push_back(line);
    }
    return out;
  }

  // Waits up to `timeout` for a line containing every one of `parts`.
  bool wait_for(const std::vector<std::string>& parts, std::chrono::milliseconds timeout) const {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (matching(parts).empty()) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return true;
  }

 private:
  static constexpr size_t kLines = 20000;
  std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> sink_;
};

}  // namespace vnsba::test
