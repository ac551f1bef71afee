// The one listener template of the node's readers (a sample taken, handed on, nothing escapes),
// made by every role of the node (node_readers.hpp) and by the action servers.
#pragma once

#include <spdlog/spdlog.h>

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/topic/TopicDescription.hpp>
#include <functional>
#include <memory>
#include <mutex>

namespace vnsba::node {

namespace dds = eprosima::fastdds::dds;

// A listener whose reader can also be emptied by a thread of the node's (take_available).
class TakingListener : public dds::DataReaderListener {
 public:
  virtual void take_available(dds::DataReader* reader) = 0;
};

// Takes every valid sample of a reader and hands it, with its SampleInfo, to `on_sample`.
// Nothing escapes it: an exception (resource exhaustion) is logged, the sample is lost to that
// exception only, and the listener goes on with the next one.
//
// Two ways to run, one take loop:
// - `on_arrival` empty: the DDS thread that delivers a sample takes it (maps, poses, tf, clock).
// - `on_arrival` set (requests and goals): the DDS thread only calls it, and the node's intake
//   thread takes, asking `may_take()` before each sample. While it says no, samples stay in the
//   reader's history, which is bounded (keep all, reader_qos), so a full history makes the remote
//   writer wait (reliable flow control) instead of the node holding an unbounded backlog. The
//   take must not run on the DDS thread then: Fast DDS 2.9 calls a listener with the reader's
//   lock held, and a second thread taking from the same reader would wait for that lock while
//   the listener waited for the second thread (a burst of 3 x 5,000 deadlocked so).
template <class Msg, class OnSample, class MayTake>
class TakeListener : public TakingListener {
 public:
  TakeListener(OnSample on_sample, MayTake may_take, std::function<void()> on_arrival)
      : on_sample_(std::move(on_sample)),
        may_take_(std::move(may_take)),
        on_arrival_(std::move(on_arrival)) {}
  void on_data_available(dds::DataReader* reader) override {
    if (on_arrival_)
      on_arrival_();
    else
      take_available(reader);
  }
  void take_available(dds::DataReader* reader) override {
    std::lock_guard<std::mutex> lock(mutex_);  // one taker at a time keeps arrival order
    Msg msg;
    dds::SampleInfo info;
    while (may_take_()) {
      try {
        if (reader->take_next_sample(&msg, &info) != ReturnCode_t::RETCODE_OK) return;
        if (info.valid_data) on_sample_(std::move(msg), info);
      } catch (const std::exception& e) {
        spdlog::critical("a sample on '{}' could not be handled: {}",
                         reader->get_topicdescription()->get_name(), e.what());
      }
      msg = Msg();
    }
  }

 private:
  std::mutex mutex_;
  OnSample on_sample_;
  MayTake may_take_;
  std::function<void()> on_arrival_;
};

template <class Msg, class OnSample>
std::unique_ptr<TakingListener> make_listener(OnSample on_sample) {
  auto always = [] { return true; };
  return std::make_unique<TakeListener<Msg, OnSample, decltype(always)>>(std::move(on_sample),
                                                                         always, nullptr);
}
// Taken by the node's intake thread, which `on_arrival` wakes, while `may_take()` holds.
template <class Msg, class OnSample, class MayTake>
std::unique_ptr<TakingListener> make_intake_listener(OnSample on_sample, MayTake may_take,
                                                     std::function<void()> on_arrival) {
  return std::make_unique<TakeListener<Msg, OnSample, MayTake>>(
      std::move(on_sample), std::move(may_take), std::move(on_arrival));
}

}  // namespace vnsba::node
