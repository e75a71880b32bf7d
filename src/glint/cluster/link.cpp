#include "glint/cluster/link.h"

#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <climits>
#include <stdexcept>
#include <utility>

#include "glint/cluster/mpi_transport.h"

namespace glint::cluster {
namespace {

double seconds(const timespec& time) {
  return static_cast<double>(time.tv_sec) + 1e-9 * static_cast<double>(time.tv_nsec);
}

double threadCpuSeconds() {
  timespec time{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &time);
  return seconds(time);
}

}  // namespace

// A message on its way out or in.
struct Link::Pending {
  std::string bytes;
  MpiRequest request;    // inactive once complete
  bool counted = false;  // sent by send(), so part of unsent_
  int peer = 0;
  int tag = 0;
};

Link::Link(MpiTransport& mpi, std::vector<int> watched, LinkTiming timing)
    : mpi_(mpi), timing_(timing) {
  const Clock::time_point now = Clock::now();
  for (const int peer : watched) watched_[peer] = Peer{now, now};
  thread_ = std::thread([this] { run(); });
  hasCpuClock_ = pthread_getcpuclockid(thread_.native_handle(), &cpuClock_) == 0;
}

Link::~Link() { stop(); }

void Link::send(int peer, Tag tag, std::string bytes) {
  if (bytes.size() > static_cast<std::size_t>(INT_MAX))
    throw std::length_error("an MPI message over 2 GiB");
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    outbox_.push_back(Message{peer, tag, std::move(bytes)});
    ++unsent_;
  }
}

std::optional<Message> Link::receive(std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!arrived_.wait_for(lock, wait, [this] { return !inbox_.empty(); })) return std::nullopt;
  Message message = std::move(inbox_.front());
  inbox_.pop_front();
  return message;
}

void Link::forget(int peer) {
  const std::lock_guard<std::mutex> lock(mutex_);
  watched_.erase(peer);
}

bool Link::flush(std::chrono::milliseconds limit) {
  std::unique_lock<std::mutex> lock(mutex_);
  return drained_.wait_for(lock, limit, [this] { return unsent_ == 0; });
}

void Link::stop() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  if (thread_.joinable()) thread_.join();
}

LinkCounters Link::counters() const {
  LinkCounters counters;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    counters = counters_;
  }
  timespec time{};
  if (hasCpuClock_ && thread_.joinable() && clock_gettime(cpuClock_, &time) == 0)
    counters.cpuSeconds = seconds(time);
  return counters;
}

void Link::run() {
  std::list<Pending> sending;
  std::list<Pending> receiving;  // in the order the messages were matched
  for (;;) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) break;
    }
    workStart_ = -1;
    bool moved = sendQueued(sending);
    moved = completeSends(sending) || moved;
    moved = receiveArrived(receiving) || moved;
    watchPeers();
    if (workStart_ >= 0) {
      const double took = threadCpuSeconds() - workStart_;
      const std::lock_guard<std::mutex> lock(mutex_);
      counters_.movingCpuSeconds += took;
    }
    if (!moved) {
      // A message under way needs this side's MPI calls to progress (a tile above the shared
      // memory's eager limit goes in fragments, each waiting for the other side's poll).
      const bool underWay = !sending.empty() || !receiving.empty();
      std::this_thread::sleep_for(underWay ? timing_.busyPoll : timing_.idlePoll);
    }
  }
  // Abandoned transfers: their peers are gone or the job is over; MPI frees the requests at exit.
  for (std::list<Pending>* transfers : {&sending, &receiving})
    for (Pending& p : *transfers) mpi_.release(p.request);
}

void Link::workStarts() {
  if (workStart_ < 0) workStart_ = threadCpuSeconds();
}

bool Link::sendQueued(std::list<Pending>& pending) {
  std::deque<Message> outgoing;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    outgoing.swap(outbox_);
    // Heartbeats to watched peers that heard nothing from us for a while.
    const Clock::time_point now = Clock::now();
    for (auto& [peer, state] : watched_) {
      if (now - state.lastSent < timing_.heartbeat) continue;
      bool queued = false;
      for (const Message& m : outgoing) queued = queued || m.peer == peer;
      if (!queued) outgoing.push_back(Message{peer, Tag::Heartbeat, {}});
    }
  }
  if (outgoing.empty()) return false;
  workStarts();
  std::uint64_t bytes = 0;
  const Clock::time_point now = Clock::now();
  std::size_t failed = 0;
  for (Message& message : outgoing) {
    const bool counted = message.tag != Tag::Heartbeat;
    // A heartbeat made here is not counted in unsent_; every send() is.
    Pending& p = pending.emplace_back(Pending{std::move(message.bytes), MpiRequest{}, counted,
                                              message.peer, static_cast<int>(message.tag)});
    bytes += p.bytes.size();
    if (!mpi_.send(p.bytes.data(), static_cast<int>(p.bytes.size()), message.peer,
                   static_cast<int>(message.tag), p.request)) {
      failed += counted ? 1 : 0;
      peerFailed(message.peer);
      pending.pop_back();
      continue;
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    if (const auto peer = watched_.find(message.peer); peer != watched_.end())
      peer->second.lastSent = now;
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    counters_.bytesSent += bytes;
    counters_.messagesSent += outgoing.size();
    unsent_ -= failed;
    if (unsent_ != 0 || failed == 0) return true;
  }
  drained_.notify_all();
  return true;
}

void Link::peerFailed(int peer) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (watched_.erase(peer) == 0) return;
    inbox_.push_back(Message{peer, Tag::Unreachable, {}});
  }
  arrived_.notify_all();
}

bool Link::completeSends(std::list<Pending>& pending) {
  if (!pending.empty()) workStarts();
  std::size_t completed = 0;
  for (auto it = pending.begin(); it != pending.end();) {
    const MpiTest state = mpi_.test(it->request);
    if (state == MpiTest::Failed) {
      // The send failed: its peer is gone. The request is freed by MPI on error.
      peerFailed(it->peer);
    }
    if (state == MpiTest::Pending) {
      ++it;
      continue;
    }
    if (it->counted) ++completed;
    it = pending.erase(it);
  }
  if (completed == 0) return false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    unsent_ -= completed;
    if (unsent_ != 0) return true;
  }
  drained_.notify_all();
  return true;
}

bool Link::receiveArrived(std::list<Pending>& receiving) {
  bool any = false;
  if (!receiving.empty()) workStarts();
  // Every message that arrived is matched (MPI_Improbe) and received without blocking
  // (MPI_Imrecv): a blocking receive of a fragmented message would spin until the sender's next
  // poll. An error here (a broken connection) is left to the silence watch.
  MpiArrival arrival;
  while (mpi_.probe(arrival)) {
    Pending& p =
        receiving.emplace_back(Pending{std::string(static_cast<std::size_t>(arrival.bytes), '\0'),
                                       MpiRequest{}, false, arrival.source, arrival.tag});
    if (!mpi_.receive(p.bytes.data(), arrival, p.request)) {
      receiving.pop_back();
      break;
    }
    any = true;
  }
  for (Pending& p : receiving) {
    if (p.request.active && mpi_.test(p.request) == MpiTest::Done) any = true;
  }
  // Delivered in the order they were matched from each peer (MPI's order), so a peer that stopped
  // halfway through a message holds back only its own later messages.
  bool delivered = false;
  std::vector<int> held;  // peers with an earlier message still under way
  for (auto it = receiving.begin(); it != receiving.end();) {
    const bool waits = std::find(held.begin(), held.end(), it->peer) != held.end();
    if (it->request.active || waits) {
      if (!waits) held.push_back(it->peer);
      ++it;
      continue;
    }
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      counters_.bytesReceived += it->bytes.size();
      ++counters_.messagesReceived;
      if (const auto peer = watched_.find(it->peer); peer != watched_.end())
        peer->second.lastHeard = Clock::now();
      if (it->tag != static_cast<int>(Tag::Heartbeat)) {
        inbox_.push_back(Message{it->peer, static_cast<Tag>(it->tag), std::move(it->bytes)});
        delivered = true;
      }
    }
    it = receiving.erase(it);
  }
  if (delivered) arrived_.notify_all();
  return any;
}

void Link::watchPeers() {
  bool reported = false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    const Clock::time_point now = Clock::now();
    for (auto it = watched_.begin(); it != watched_.end();) {
      if (now - it->second.lastHeard <= timing_.timeout) {
        ++it;
        continue;
      }
      inbox_.push_back(Message{it->first, Tag::Silent, {}});
      it = watched_.erase(it);
      reported = true;
    }
  }
  if (reported) arrived_.notify_all();
}

}  // namespace glint::cluster
