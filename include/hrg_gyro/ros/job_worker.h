// One thread serving jobs in order, off the callback threads: the calibrators' reload workers (a
// service call may block for seconds; the callbacks must not). Jobs are pushed from any thread; the
// worker takes them one at a time. A job that waits for something else (a message the node
// receives meanwhile) waits under the worker's lock with waitUntil, and whoever changes what it
// waits for does so through update(); stop() wakes either wait and ends the thread after the job in
// hand (jobs not yet taken are dropped).
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

namespace hrg_gyro {

template <class Job>
class JobWorker {
 public:
  JobWorker() = default;
  ~JobWorker() { stop(); }
  JobWorker(const JobWorker&) = delete;
  JobWorker& operator=(const JobWorker&) = delete;

  /// Starts the thread: `serve(job)` for every job pushed, in order, until stop().
  void start(std::function<void(Job&)> serve) {
    thread_ = std::thread([this, serve = std::move(serve)] {
      for (;;) {
        Job job;
        {
          std::unique_lock<std::mutex> lock(mutex_);
          cv_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
          if (stopping_) return;
          job = std::move(jobs_.front());
          jobs_.pop_front();
        }
        serve(job);
      }
    });
  }
  void push(Job job) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      jobs_.push_back(std::move(job));
    }
    cv_.notify_all();
  }
  /// Runs `change` under the worker's lock and wakes a job waiting in waitUntil.
  template <class Change>
  void update(Change&& change) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      change();
    }
    cv_.notify_all();
  }
  /// From a job: waits under the worker's lock until `ready()` (called under it), at most `timeout`;
  /// false when it timed out or the worker is stopping.
  template <class Ready>
  bool waitUntil(std::chrono::milliseconds timeout, Ready&& ready) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, timeout, [&] { return stopping_ || ready(); }) && !stopping_;
  }
  bool stopping() {
    std::lock_guard<std::mutex> lock(mutex_);
    return stopping_;
  }
  /// Wakes the waits and joins the thread (after the job in hand); idempotent.
  void stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Job> jobs_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace hrg_gyro
