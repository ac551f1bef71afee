// The topic table's QoS over loopback: what the profiles promise (ARCHITECTURE.md).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "node/bus_client.hpp"

namespace vnsba::test {
namespace {

using node::TopicQos;

// Counts the samples a reader takes, as the node's listeners do (take at once, never plan).
class CountingListener : public node::dds::DataReaderListener {
 public:
  void on_data_available(node::dds::DataReader* reader) override {
    node::PlanRequestMsg msg;
    node::dds::SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) ++taken;
  }
  std::atomic<int> taken{0};
};

// Issue 13: a client bursting 3,000 requests lost the one at index 2,048: with the events
// profile (reliable, keep all, 2,048 samples) write() returned false at once when the history
// was full of unacknowledged samples instead of blocking until the reader acknowledged some.
// Every write of a burst larger than the history must succeed, and every sample arrive.
TEST(DdsQos, AnEventsBurstLargerThanTheHistoryIsNeverDropped) {
  const int domain = test_domain();
  const std::string topic_name = "t" + std::to_string(getpid()) + "_qos_burst";
  auto writer_side = node::Participant::create(domain, "burst_writer").value();
  auto reader_side = node::Participant::create(domain, "burst_reader").value();
  auto wt = writer_side->topic<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(topic_name).value();
  auto rt = reader_side->topic<vnsba_msgs::msg::dds_::PlanRequest_PubSubType>(topic_name).value();
  CountingListener listener;
  ASSERT_TRUE(reader_side->reader(rt, node::reader_qos(TopicQos::kEvents), &listener));
  auto writer = writer_side->writer(wt, node::writer_qos(TopicQos::kEvents, false)).value();
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (node::matched_readers(writer) < 1 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(10ms);
  ASSERT_EQ(node::matched_readers(writer), 1);
  constexpr int kBurst = 3000;
  int failed = 0, first_failed = -1;
  for (int i = 0; i < kBurst; ++i) {
    node::PlanRequestMsg msg;
    msg.id("burst-" + std::to_string(i));
    if (!writer->write(&msg)) {
      ++failed;
      if (first_failed < 0) first_failed = i;
    }
  }
  EXPECT_EQ(failed, 0) << "first failed write at index " << first_failed;
  while (listener.taken < kBurst && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(10ms);
  EXPECT_EQ(listener.taken, kBurst);
  writer_side->shutdown();
  reader_side->shutdown();
}

}  // namespace
}  // namespace vnsba::test
