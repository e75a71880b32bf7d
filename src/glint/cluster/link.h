// The one thread that makes MPI calls while a rank runs (MPI_THREAD_SERIALIZED): it sends queued
// messages without blocking (MPI_Isend), takes in every message that arrives (MPI_Improbe and
// MPI_Imrecv; a tile above the eager limit comes in fragments over several polls), sends
// heartbeats, and reports a watched peer that stays silent longer than the timeout. Nothing in it
// waits on MPI, so no rank can hang on a peer that died or stopped.
#pragma once

#include <time.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <list>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "glint/cluster/protocol.h"

#include "glint/cluster/mpi_transport.h"

namespace glint::cluster {

struct LinkTiming {
  // A heartbeat goes to a watched peer when nothing else went to it for this long.
  std::chrono::milliseconds heartbeat{1000};
  // A watched peer that sent nothing for this long is reported (Tag::Silent).
  std::chrono::milliseconds timeout{20000};
  // The sleep between polls when nothing happened: the latency of a reply.
  std::chrono::microseconds idlePoll{1000};
  // ... while a message is under way, which this side's polls move along.
  std::chrono::microseconds busyPoll{20};
};

struct Message {
  int peer = 0;
  Tag tag = Tag::Heartbeat;
  std::string bytes;
};

struct LinkCounters {
  std::uint64_t bytesSent = 0;  // payloads, heartbeats included
  std::uint64_t bytesReceived = 0;
  std::uint64_t messagesSent = 0;
  std::uint64_t messagesReceived = 0;
  double cpuSeconds = 0;        // the CPU time of the link's thread so far: every poll
  double movingCpuSeconds = 0;  // of which in polls with a message to send, under way or received
};

class Link {
 public:
  // Starts the thread; MPI must be initialised (through `mpi`) and this process must make no other
  // MPI call until stop(). `watched`: the peers whose silence is reported and who get heartbeats.
  Link(MpiTransport& mpi, std::vector<int> watched, LinkTiming timing);
  ~Link();
  Link(const Link&) = delete;
  Link& operator=(const Link&) = delete;

  // Queues a message to `peer` (any thread).
  void send(int peer, Tag tag, std::string bytes);
  // The next message that arrived (heartbeats excluded; a silent peer as Tag::Silent, one whose
  // send failed as Tag::Unreachable), waiting up to `wait`.
  std::optional<Message> receive(std::chrono::milliseconds wait);
  // `peer` has said its last word or was told to stop: no more heartbeats to it, and its silence is
  // no longer reported.
  void forget(int peer);
  // Waits up to `limit` until every message queued so far has been delivered to MPI and completed;
  // false when some are still pending (their peer may be gone).
  bool flush(std::chrono::milliseconds limit);
  // Ends the thread; pending sends are abandoned. Afterwards the caller may call MPI again.
  void stop();

  LinkCounters counters() const;

 private:
  using Clock = std::chrono::steady_clock;
  struct Pending;
  struct Peer {
    Clock::time_point lastHeard;
    Clock::time_point lastSent;
  };
  void run();
  // Marks that this poll has work: its CPU time from here on counts as moving messages. An idle
  // poll does not read the clock, so it stays cheap.
  void workStarts();
  bool sendQueued(std::list<Pending>& pending);
  bool completeSends(std::list<Pending>& pending);
  bool receiveArrived(std::list<Pending>& receiving);
  void watchPeers();
  // A send to `peer` failed: it is reported (Tag::Unreachable) and no longer watched.
  void peerFailed(int peer);

  MpiTransport& mpi_;
  LinkTiming timing_;
  mutable std::mutex mutex_;
  std::condition_variable arrived_;  // inbox_ grew
  std::condition_variable drained_;  // unsent_ fell to 0
  std::deque<Message> outbox_;
  std::deque<Message> inbox_;
  std::size_t unsent_ = 0;  // messages queued by send() and not yet completed
  std::map<int, Peer> watched_;
  LinkCounters counters_;  // cpuSeconds filled in by counters()
  bool stopping_ = false;
  std::thread thread_;
  clockid_t cpuClock_{};   // the thread's CPU-time clock
  double workStart_ = -1;  // the link thread's CPU time when this poll's work began; -1: none
  bool hasCpuClock_ = false;
};

}  // namespace glint::cluster
