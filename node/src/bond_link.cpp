#include "vnsba/node/bond_link.hpp"

#include <spdlog/spdlog.h>

#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "bond/msg/StatusPubSubTypes.h"
#include "take_listener.hpp"
#include "vnsba/node/convert.hpp"

namespace vnsba::node {

namespace {

using BondStatusMsg = bond::msg::dds_::Status_;

BondHeartbeat heartbeat_of(const BondStatusMsg& msg) {
  BondHeartbeat h;
  h.id = msg.id();
  h.instance_id = msg.instance_id();
  h.active = msg.active();
  h.heartbeat_timeout_s = msg.heartbeat_timeout();
  h.heartbeat_period_s = msg.heartbeat_period();
  return h;
}

}  // namespace

class BondLink::Impl {
 public:
  using Clock = Bond::Clock;

  core::Status create(Participant& participant, const std::string& dds_topic) {
    // bondcpp: publisher rclcpp::QoS(rclcpp::KeepLast(5)), subscription rclcpp::QoS(100), both
    // rclcpp's defaults otherwise: reliable, volatile.
    dds::DataWriterQos wqos = writer_qos(TopicQos::kLatest, /*large_samples=*/false);
    wqos.history().depth = 5;
    dds::DataReaderQos rqos = reader_qos(TopicQos::kLatest);
    rqos.history().depth = 100;
    auto writer = participant.writer_on<bond::msg::dds_::Status_PubSubType>(dds_topic, wqos);
    if (!writer) return writer.error();
    writer_ = *writer;
    listener_ = make_listener<BondStatusMsg>(
        [this](BondStatusMsg&& msg, const dds::SampleInfo&) { on_status(msg); });
    auto reader =
        participant.reader_on<bond::msg::dds_::Status_PubSubType>(dds_topic, rqos, listener_.get());
    if (!reader) return reader.error();
    reader_ = *reader;
    thread_ = std::thread([this] { run(); });
    return core::Status::ok();
  }

  void start(const std::string& id, const BondTimings& timings, OnFormed on_formed,
             OnBroken on_broken) {
    break_bond(std::chrono::milliseconds(0));
    {
      std::lock_guard<std::mutex> lock(mutex_);
      bond_ = std::make_unique<Bond>(id, new_instance_id(), timings);
      on_formed_ = std::move(on_formed);
      on_broken_ = std::move(on_broken);
      handle(bond_->start(Clock::now()));  // starting publishes nothing and calls nothing
    }
    changed_.notify_all();
  }

  void break_bond(std::chrono::milliseconds wait) {
    Announcement announce;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!bond_) return;
      announce = handle(bond_->break_bond(Clock::now()));
    }
    announce();  // before the waiters wake: whoever waited for the state sees its callback done
    changed_.notify_all();
    if (wait.count() > 0) wait_for(wait, [](BondState st) { return st == BondState::kDead; });
  }

  BondState state() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return bond_ ? bond_->state() : BondState::kNotStarted;
  }

  template <class Done>
  bool wait_for(std::chrono::milliseconds timeout, Done done) const {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return bond_ && done(bond_->state()); });
  }

  std::string instance_id() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return bond_ ? bond_->instance_id() : std::string();
  }

  uint64_t heartbeats_written() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return written_;
  }

  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
    // The reader first: no listener call after this.
    // DataReader::get_subscriber() gives a const pointer to the (mutable) subscriber that made it.
    if (reader_ != nullptr)
      const_cast<dds::Subscriber*>(reader_->get_subscriber())->delete_datareader(reader_);
    reader_ = nullptr;
    std::lock_guard<std::mutex> lock(mutex_);
    if (writer_ != nullptr)
      const_cast<dds::Publisher*>(writer_->get_publisher())->delete_datawriter(writer_);
    writer_ = nullptr;
  }

 private:
  void on_status(const BondStatusMsg& msg) {
    Announcement announce;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // The bond topic carries every server's heartbeats and our own (every 0.1 s each): only
      // those of our bond's id wake anyone.
      if (!bond_ || msg.id() != bond_->id()) return;
      announce = handle(bond_->on_status(heartbeat_of(msg), Clock::now()));
    }
    announce();  // before the waiters wake: whoever waited for the state sees its callback done
    changed_.notify_all();
  }

  // The link's thread: the bond's timers.
  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stopping_) {
      const std::optional<Bond::TimePoint> due = bond_ ? bond_->next_deadline() : std::nullopt;
      if (due)
        changed_.wait_until(lock, *due);
      else
        changed_.wait(lock);
      if (stopping_ || !bond_) continue;
      const Announcement announce = handle(bond_->advance(Clock::now()));
      lock.unlock();
      announce();
      changed_.notify_all();
      lock.lock();
    }
  }

  // What a step's events call, taken under the lock and called without it.
  struct Announcement {
    OnFormed formed;
    std::string sister;
    OnBroken broken;
    BondEnd why = BondEnd::kBrokenHere;
    void operator()() const {
      if (formed) formed(sister);
      if (broken) broken(why);
    }
  };

  // Writes what the step says to publish (with the lock held: one writer of heartbeats at a
  // time, in order) and takes the callbacks its events call for.
  Announcement handle(const BondStep& step) {
    for (const BondHeartbeat& h : step.publish) {
      BondStatusMsg msg;
      // bondcpp stamps with the steady clock; nobody reads the stamp. ROS time here.
      msg.header().stamp(now_msg());
      msg.id(h.id);
      msg.instance_id(h.instance_id);
      msg.active(h.active);
      msg.heartbeat_timeout(h.heartbeat_timeout_s);
      msg.heartbeat_period(h.heartbeat_period_s);
      if (writer_ != nullptr && write_sample(writer_, &msg)) ++written_;
    }
    Announcement a;
    if (step.formed) {
      a.formed = on_formed_;
      a.sister = bond_->sister_instance_id();
    }
    if (step.ended) {
      a.broken = on_broken_;
      a.why = *step.ended;
    }
    return a;
  }

  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::unique_ptr<Bond> bond_;
  OnFormed on_formed_;
  OnBroken on_broken_;
  uint64_t written_ = 0;
  bool stopping_ = false;
  dds::DataWriter* writer_ = nullptr;
  dds::DataReader* reader_ = nullptr;
  std::unique_ptr<TakingListener> listener_;
  std::thread thread_;
};

core::Expected<std::unique_ptr<BondLink>> BondLink::create(Participant& participant,
                                                           const std::string& dds_topic) {
  auto impl = std::make_unique<Impl>();
  if (core::Status s = impl->create(participant, dds_topic); !s.is_ok()) {
    impl->close();
    return s;
  }
  return std::unique_ptr<BondLink>(new BondLink(std::move(impl)));
}

BondLink::BondLink(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BondLink::~BondLink() {
  close();
}

void BondLink::start(const std::string& id, const BondTimings& timings, OnFormed on_formed,
                     OnBroken on_broken) {
  impl_->start(id, timings, std::move(on_formed), std::move(on_broken));
}
void BondLink::break_bond(std::chrono::milliseconds wait) {
  impl_->break_bond(wait);
}
BondState BondLink::state() const {
  return impl_->state();
}
bool BondLink::wait_until_formed(std::chrono::milliseconds timeout) const {
  return impl_->wait_for(timeout, [](BondState s) { return s != BondState::kWaitingForSister; });
}
bool BondLink::wait_until_broken(std::chrono::milliseconds timeout) const {
  return impl_->wait_for(timeout, [](BondState s) { return s == BondState::kDead; });
}
std::string BondLink::instance_id() const {
  return impl_->instance_id();
}
uint64_t BondLink::heartbeats_written() const {
  return impl_->heartbeats_written();
}
void BondLink::close() {
  impl_->close();
}

}  // namespace vnsba::node
