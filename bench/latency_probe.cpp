// Bench-only node: measures the live pipeline from the outside. Subscribes `output` (and the
// processor's /diagnostics for the samples it saw lost on its input), and for ~duration wall seconds after the first
// output records the end-to-end latency (wall time of arrival minus the driver's stamp, which driver_sim takes from the
// wall clock when not under sim time) and the outputs missing from the stamp sequence. Then writes ~result_file (YAML)
// and exits, which ends a launch that marks it required.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

#include "hrg_gyro/GyroOutput.h"

namespace {

struct Probe {
  double duration = 60.0, rate = 1000.0;
  std::vector<double> latency;  // s
  std::uint64_t outputs = 0, output_missing = 0;
  long long input_lost = -1;  // the processor's "lost (sequence gaps)", -1 until reported
  ros::Time first_stamp, last_stamp;
  ros::WallTime started;
  bool running = false, finished = false;

  void onOutput(const hrg_gyro::GyroOutput::ConstPtr& m) {
    const ros::WallTime now = ros::WallTime::now();
    if (finished) return;
    if (!running) {
      running = true;
      started = now;
      first_stamp = m->header.stamp;
    } else {
      // outputs come one per channel sample, 1/rate apart
      const double step = (m->header.stamp - last_stamp).toSec() * rate;
      if (step > 1.5) output_missing += static_cast<std::uint64_t>(std::lround(step)) - 1;
    }
    last_stamp = m->header.stamp;
    ++outputs;
    latency.push_back(now.toSec() - m->header.stamp.toSec());
    if ((now - started).toSec() >= duration) finished = true;
  }
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
    for (const auto& status : m->status) {
      for (const auto& kv : status.values) {
        if (kv.key == "lost (sequence gaps)") input_lost = std::atoll(kv.value.c_str());
      }
    }
  }
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + i, v.end());
  return v[i];
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "latency_probe");
  ros::NodeHandle nh, pnh("~");
  Probe probe;
  std::string result_file;
  pnh.param("duration", probe.duration, probe.duration);
  pnh.param("rate", probe.rate, probe.rate);
  pnh.param<std::string>("result_file", result_file, "latency.yaml");
  probe.latency.reserve(static_cast<std::size_t>(probe.duration * probe.rate * 1.2));
  ros::Subscriber out = nh.subscribe("output", 100000, &Probe::onOutput, &probe, ros::TransportHints().tcpNoDelay());
  ros::Subscriber diag = nh.subscribe("/diagnostics", 100, &Probe::onDiagnostics, &probe);
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(probe.duration + 60.0);
  while (ros::ok() && !probe.finished && ros::WallTime::now() < give_up) {
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.01));
  }
  const double span = (probe.last_stamp - probe.first_stamp).toSec();
  std::ofstream f(result_file);
  f << "rate: " << probe.rate << "\n"
    << "seconds: " << span << "\n"
    << "outputs: " << probe.outputs << "\n"
    << "outputs_missing: " << probe.output_missing << "\n"
    << "processor_input_lost: " << probe.input_lost << "\n"
    << "latency_p50_ms: " << 1e3 * percentile(probe.latency, 0.5) << "\n"
    << "latency_p99_ms: " << 1e3 * percentile(probe.latency, 0.99) << "\n"
    << "latency_max_ms: " << 1e3 * percentile(probe.latency, 1.0) << "\n"
    << "completed: " << (probe.finished ? "true" : "false") << "\n";
  ROS_INFO("latency_probe: %lu outputs, %lu missing, p50 %.3f ms, p99 %.3f ms -> %s", (unsigned long)probe.outputs,
           (unsigned long)probe.output_missing, 1e3 * percentile(probe.latency, 0.5),
           1e3 * percentile(probe.latency, 0.99), result_file.c_str());
  return probe.finished ? 0 : 1;
}
