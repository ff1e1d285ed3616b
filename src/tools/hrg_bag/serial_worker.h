// One background thread that runs submitted jobs one after the other, in order. hrg_bag hands it
// the output work (formatting CSV rows, compressing and writing bag chunks) so that on a machine
// with two cores it overlaps with reading and processing the input. At most `max_pending` jobs wait;
// submit() blocks beyond that, so memory stays bounded. The first exception a job throws is kept and
// rethrown, with its type, by the next submit() or finish(); later jobs are then skipped.
#pragma once

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace hrg_gyro {
namespace bag_tools {

class SerialWorker {
 public:
  explicit SerialWorker(std::size_t max_pending = 2)
      : max_pending_(max_pending), thread_([this] {
          // Below the thread that reads the input: on two cores the reader is the stage every other one
          // waits for, so when the stages outnumber the cores it is the one that keeps its core.
          ::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), kNiceness);
          run();
        }) {}
  /// Waits for the running job; the jobs still waiting are dropped (an abandoned output).
  ~SerialWorker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      jobs_.clear();
      stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  SerialWorker(const SerialWorker&) = delete;
  SerialWorker& operator=(const SerialWorker&) = delete;

  void submit(std::function<void()> job) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return jobs_.size() < max_pending_ || error_; });
    rethrow();
    jobs_.push_back(std::move(job));
    changed_.notify_all();
  }

  /// Waits until every submitted job has run; rethrows the first failure.
  void finish() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return (jobs_.empty() && !busy_) || error_; });
    rethrow();
  }

 private:
  static constexpr int kNiceness = 5;
  void rethrow() {
    if (error_) std::rethrow_exception(error_);
  }
  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      changed_.wait(lock, [this] { return !jobs_.empty() || stopping_; });
      if (jobs_.empty()) return;  // stopping
      std::function<void()> job = std::move(jobs_.front());
      jobs_.pop_front();
      busy_ = true;
      lock.unlock();
      std::exception_ptr error;
      try {
        job();
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      busy_ = false;
      if (error) {
        if (!error_) error_ = error;
        jobs_.clear();
      }
      changed_.notify_all();
    }
  }

  const std::size_t max_pending_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> jobs_;
  bool busy_ = false, stopping_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: started once everything above is ready
};

}  // namespace bag_tools
}  // namespace hrg_gyro
