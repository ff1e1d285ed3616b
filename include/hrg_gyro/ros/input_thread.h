// A callback queue and a thread of their own for a node's high-rate input subscriptions.
//
// In a nodelet manager every callback of every nodelet goes through the manager's dispatcher and a
// small pool of workers, and a nodelet's single-threaded queue stays on one worker while it has work:
// at 10 kHz the processor and the calibrator could end up sharing one worker behind each other's
// backlog (measured: the processor 1.4 s behind its input while the other worker idled). Here the
// inputs are served by one dedicated thread, in arrival order, in a node and in a nodelet alike;
// timers and services stay on the node's usual queue. Callbacks still lock the node's own mutex.
#pragma once

#include <ros/callback_queue.h>
#include <ros/ros.h>

namespace hrg_gyro {

class InputThread {
 public:
  InputThread() : spinner_(1, &queue_) {}
  ~InputThread() { stop(); }
  InputThread(const InputThread&) = delete;
  InputThread& operator=(const InputThread&) = delete;

  /// A handle like `nh` whose subscriptions are served by this thread.
  ros::NodeHandle handle(const ros::NodeHandle& nh) {
    ros::NodeHandle h(nh);
    h.setCallbackQueue(&queue_);
    return h;
  }
  void start() { spinner_.start(); }
  /// Waits for the callback in flight; call after shutting the subscriptions down and before the
  /// state the callbacks use is destroyed.
  void stop() {
    spinner_.stop();
    queue_.disable();
    queue_.clear();
  }

 private:
  ros::CallbackQueue queue_;
  ros::AsyncSpinner spinner_;
};

}  // namespace hrg_gyro
