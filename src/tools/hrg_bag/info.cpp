// hrg_bag info: is this a usable gyro bag? Topics and types, counts, rates and the dt histogram,
// gaps, stamp order, lost sequence numbers, header vs record time. Non-zero exit on errors. A bag of
// an IMU's log (sensor_msgs/Imu, no gyro channels, as `hrg_bag import --imu` writes) gets the same
// checks on its Imu topics.
#include <sensor_msgs/Imu.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <vector>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "hrg_gyro/GroundTruth.h"
#include "hrg_gyro/TurntableState.h"
#include "read_messages.h"

namespace hrg_gyro {
namespace {

struct StampStats {
  std::uint64_t count = 0, zero = 0, duplicate = 0, backwards = 0, seq_lost = 0;
  double first = 0.0, last = 0.0, max_record_lag = 0.0;
  std::vector<double> dts;
  bool has_prev = false;
  double prev = 0.0;
  std::uint32_t prev_seq = 0;

  void add(const std_msgs::Header& h, const ros::Time& record) {
    ++count;
    const double t = h.stamp.toSec();
    if (h.stamp.isZero()) {
      ++zero;
      return;
    }
    max_record_lag = std::max(max_record_lag, std::abs(record.toSec() - t));
    if (has_prev) {
      if (t == prev)
        ++duplicate;
      else if (t < prev)
        ++backwards;
      else
        dts.push_back(t - prev);
      if (h.seq > prev_seq + 1) seq_lost += h.seq - prev_seq - 1;
    } else {
      first = t;
    }
    has_prev = true;
    prev = std::max(prev, t);
    last = prev;
    prev_seq = h.seq;
  }
};

template <typename M>
StampStats scan(const rosbag::Bag& bag, const std::string& topic) {
  StampStats s;
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  bag_tools::readMessages(view, nullptr, [&s](const rosbag::MessageInstance& m) {
    const typename M::ConstPtr msg = m.instantiate<M>();
    if (msg) s.add(msg->header, m.getTime());
  });
  return s;
}

struct InfoOptions {
  std::string bag;
  bag_tools::GyroTopics topics;
  double gap_factor = 3.0;
};

/// What the streams' checks found: an error makes the bag INVALID, a warning is said.
struct Verdict {
  int errors = 0, warnings = 0;
};

/// One stream's stamps on stdout: its rate, the spread of its intervals against the median, its
/// gaps (above `gap_factor` x the median) and its bad stamps, counted into `v` (as errors when the
/// stream is `required`).
void reportStream(const std::string& name, const StampStats& s, bool required, double gap_factor, Verdict* v) {
  int& errors = v->errors;
  int& warnings = v->warnings;
  std::printf("%s (%s): %lu messages\n", name.c_str(), name.c_str(), static_cast<unsigned long>(s.count));
  if (s.dts.empty()) {
    if (required) {
      std::printf("  ERROR: fewer than two valid stamps\n");
      ++errors;
    }
    return;
  }
  std::vector<double> sorted = s.dts;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::printf("  span %.3f s, median dt %.6f s (%.2f Hz), mean rate %.2f Hz\n", s.last - s.first, median, 1.0 / median,
              (s.count - 1) / std::max(1e-12, s.last - s.first));
  const double edges[] = {0.0, 0.5, 0.9, 1.1, 2.0, 10.0, INFINITY};
  std::uint64_t counts[6] = {0, 0, 0, 0, 0, 0};
  std::uint64_t gaps = 0;
  double largest = 0.0;
  for (double dt : s.dts) {
    const double r = dt / median;
    for (int b = 0; b < 6; ++b) {
      if (r >= edges[b] && r < edges[b + 1]) ++counts[b];
    }
    if (r > gap_factor) ++gaps;
    largest = std::max(largest, dt);
  }
  std::printf("  dt / median: <0.5 %lu | 0.5-0.9 %lu | 0.9-1.1 %lu | 1.1-2 %lu | 2-10 %lu | >10 %lu\n",
              static_cast<unsigned long>(counts[0]), static_cast<unsigned long>(counts[1]),
              static_cast<unsigned long>(counts[2]), static_cast<unsigned long>(counts[3]),
              static_cast<unsigned long>(counts[4]), static_cast<unsigned long>(counts[5]));
  std::printf("  gaps above %.1f x median: %lu (largest %.6f s); lost sequence numbers: %lu\n", gap_factor,
              static_cast<unsigned long>(gaps), largest, static_cast<unsigned long>(s.seq_lost));
  std::printf("  header vs record time: largest difference %.6f s\n", s.max_record_lag);
  if (gaps || s.seq_lost) ++warnings;
  if (s.zero || s.duplicate || s.backwards) {
    std::printf("  ERROR: %lu zero, %lu duplicate, %lu backward stamps\n", static_cast<unsigned long>(s.zero),
                static_cast<unsigned long>(s.duplicate), static_cast<unsigned long>(s.backwards));
    if (required)
      ++errors;
    else
      ++warnings;
  }
}

int runInfo(const InfoOptions& o) {
  using namespace bag_tools;
  const std::unique_ptr<rosbag::Bag> bag = openBag(o.bag);
  rosbag::View all(*bag);
  std::map<std::string, std::pair<std::string, std::uint64_t>> topics;
  for (const rosbag::ConnectionInfo* c : all.getConnections()) topics[c->topic].first = c->datatype;
  for (const auto& kv : topics) topics[kv.first].second = rosbag::View(*bag, rosbag::TopicQuery(kv.first)).size();
  std::printf("bag %s: %.3f s, %u messages\n", o.bag.c_str(), (all.getEndTime() - all.getBeginTime()).toSec(),
              all.size());
  for (const auto& kv : topics)
    std::printf("  %-28s %-34s %10lu\n", kv.first.c_str(), kv.second.first.c_str(),
                static_cast<unsigned long>(kv.second.second));
  Verdict v;
  auto report = [&](const std::string& name, const StampStats& s, bool required) {
    reportStream(name, s, required, o.gap_factor, &v);
  };
  // A bag of an IMU's log (hrg_bag import --imu) holds no channels: its sensor_msgs/Imu topics are what
  // is validated, each as channels would be.
  std::vector<std::string> imu_topics;
  bool has_channels = false;
  for (const auto& kv : topics) {
    if (kv.second.first == "hrg_gyro/ChannelAmplitudes") has_channels = true;
    if (kv.second.first == "sensor_msgs/Imu") imu_topics.push_back(kv.first);
  }
  if (!has_channels && !imu_topics.empty() && o.topics.channels.empty()) {
    for (const std::string& topic : imu_topics) report(topic, scan<sensor_msgs::Imu>(*bag, topic), true);
    std::printf("%s: %d error(s), %d warning(s) (an IMU bag: no gyro channels)\n", v.errors ? "INVALID" : "OK",
                v.errors, v.warnings);
    return v.errors ? 1 : 0;
  }
  GyroTopics t;
  try {
    t = findTopics(*bag, o.topics, true, false);
  } catch (const UsageError& e) {
    std::printf("ERROR: %s\n", e.what());
    return 1;
  }
  report(t.channels, scan<ChannelAmplitudes>(*bag, t.channels), true);
  if (!t.turntable.empty()) {
    report(t.turntable, scan<TurntableState>(*bag, t.turntable), false);
  } else {
    std::printf("WARNING: no TurntableState topic: the bag can be processed but not calibrated\n");
    ++v.warnings;
  }
  if (!t.truth.empty()) report(t.truth, scan<GroundTruth>(*bag, t.truth), false);
  std::printf("%s: %d error(s), %d warning(s)\n", v.errors ? "INVALID" : "OK", v.errors, v.warnings);
  return v.errors ? 1 : 0;
}

}  // namespace

namespace bag_tools {

Command addInfoCommand(CLI::App& root) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* cmd = root.add_subcommand("info", "is this a usable gyro bag? rates, gaps, stamp order, losses");
  cmd->add_option("BAG", o->bag, "the bag to validate")->required();
  addTopicOptions(*cmd, &o->topics, true);
  cmd->add_option("--gap", o->gap_factor, "> 1: a stamp step above this many median steps counts as a gap")
      ->transform(tools::finiteNumber())
      ->check(tools::above(1.0))
      ->capture_default_str();
  cmd->footer(
      "Validates a gyro bag: topics and types, counts, rates and dt histogram, gaps, stamp order, lost\n"
      "sequence numbers, header vs record time.\n"
      "A bag without gyro channels but with sensor_msgs/Imu topics (hrg_bag import --imu) gets the\n"
      "same checks on each Imu topic.\n"
      "Exit 0 usable, 1 when the bag cannot be processed as it is (no channels, bad stamps),\n"
      "2 bad usage or unreadable bag.");
  return [o] { return runInfo(*o); };
}

}  // namespace bag_tools
}  // namespace hrg_gyro
