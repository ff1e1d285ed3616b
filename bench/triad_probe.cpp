// Bench-only node: watches the triad from the outside (bench/live_triad.launch). Subscribes
// `triad/output` and /diagnostics and, for ~duration wall seconds after the first triad sample,
// counts the samples, those combined from three axes, the flagged ones and the stamps missing from
// the 1/~rate sequence; reads each processor's "lost (sequence gaps)" and the triad's per-axis
// "missing stamps" from the diagnostics; and measures how far each sample is behind /clock on
// arrival (sim time: the drivers stamp in it; 1 ms steps at 10 kHz with an automatic clock period)
// and how fast sim time ran against the wall clock (below 1: the pipeline slowed the simulated
// clock instead of dropping samples). Then writes ~result_file (YAML) and exits, which ends a
// launch that marks it required.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "hrg_gyro/TriadOutput.h"

namespace {

struct Probe {
  double duration = 60.0, rate = 10000.0;
  std::vector<double> behind;  // s of sim time
  std::uint64_t samples = 0, combined = 0, flagged = 0, missing = 0;
  std::map<std::string, long long> lost, axis_missing;  // from the diagnostics, by status name
  ros::Time first_stamp, last_stamp;
  ros::WallTime started;
  bool running = false, finished = false;

  void onOutput(const hrg_gyro::TriadOutput::ConstPtr& m) {
    const ros::WallTime now = ros::WallTime::now();
    if (finished) return;
    if (!running) {
      running = true;
      started = now;
      first_stamp = m->header.stamp;
    } else {
      const double step = (m->header.stamp - last_stamp).toSec() * rate;
      if (step > 1.5) missing += static_cast<std::uint64_t>(std::lround(step)) - 1;
    }
    last_stamp = m->header.stamp;
    ++samples;
    if (m->flags & (hrg_gyro::TriadOutput::FLAG_GAP | hrg_gyro::TriadOutput::FLAG_RESET)) {
      ++flagged;
    } else {
      ++combined;
    }
    behind.push_back((ros::Time::now() - m->header.stamp).toSec());
    if ((now - started).toSec() >= duration) finished = true;
  }
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
    for (const auto& status : m->status) {
      for (const auto& kv : status.values) {
        if (kv.key == "lost (sequence gaps)") lost[status.name] = std::atoll(kv.value.c_str());
        if (kv.key == "missing stamps") axis_missing[status.name] = std::atoll(kv.value.c_str());
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

long long sum(const std::map<std::string, long long>& m) {
  long long s = 0;
  for (const auto& kv : m) s += kv.second;
  return m.empty() ? -1 : s;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "triad_probe");
  ros::NodeHandle nh, pnh("~");
  Probe probe;
  std::string result_file;
  pnh.param("duration", probe.duration, probe.duration);
  pnh.param("rate", probe.rate, probe.rate);
  pnh.param<std::string>("result_file", result_file, "triad.yaml");
  probe.behind.reserve(static_cast<std::size_t>(probe.duration * probe.rate * 1.2));
  ros::Subscriber out =
      nh.subscribe("triad/output", 100000, &Probe::onOutput, &probe, ros::TransportHints().tcpNoDelay());
  ros::Subscriber diag = nh.subscribe("/diagnostics", 100, &Probe::onDiagnostics, &probe);
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(probe.duration + 120.0);
  while (ros::ok() && !probe.finished && ros::WallTime::now() < give_up) {
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.01));
  }
  // The last diagnostics round after the window (the counters are cumulative).
  const ros::WallTime settle = ros::WallTime::now() + ros::WallDuration(2.5);
  while (ros::ok() && ros::WallTime::now() < settle) {
    ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.01));
  }
  const double span = (probe.last_stamp - probe.first_stamp).toSec();
  const double wall = (ros::WallTime::now() - probe.started).toSec() - 2.5;
  std::ofstream f(result_file);
  f << "rate: " << probe.rate << "\n"
    << "seconds: " << span << "\n"
    << "wall_seconds: " << wall << "\n"
    << "sim_per_wall: " << (wall > 0.0 ? span / wall : 0.0) << "\n"
    << "samples: " << probe.samples << "\n"
    << "expected: " << static_cast<std::uint64_t>(std::llround(span * probe.rate)) + 1 << "\n"
    << "combined: " << probe.combined << "\n"
    << "flagged: " << probe.flagged << "\n"
    << "stamps_missing: " << probe.missing << "\n"
    << "processors_input_lost: " << sum(probe.lost) << "\n"
    << "triad_axis_missing: " << sum(probe.axis_missing) << "\n"
    << "behind_clock_p50_ms: " << 1e3 * percentile(probe.behind, 0.5) << "\n"
    << "behind_clock_p99_ms: " << 1e3 * percentile(probe.behind, 0.99) << "\n"
    << "behind_clock_max_ms: " << 1e3 * percentile(probe.behind, 1.0) << "\n"
    << "completed: " << (probe.finished ? "true" : "false") << "\n";
  ROS_INFO("triad_probe: %lu samples, %lu combined, %lu flagged, %lu missing, sim/wall %.3f -> %s",
           (unsigned long)probe.samples, (unsigned long)probe.combined, (unsigned long)probe.flagged,
           (unsigned long)probe.missing, wall > 0.0 ? span / wall : 0.0, result_file.c_str());
  return probe.finished ? 0 : 1;
}
