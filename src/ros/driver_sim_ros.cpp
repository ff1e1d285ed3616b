#include "hrg_gyro/ros/driver_sim_ros.h"

#include <rosgraph_msgs/Clock.h>
#include <std_msgs/Bool.h>
#include <std_msgs/Time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hrg_gyro/BodyTruth.h"
#include "hrg_gyro/ChannelAmplitudes.h"
#include "hrg_gyro/FixturePosition.h"
#include "hrg_gyro/GroundTruth.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/ros/conversions.h"
#include "hrg_gyro/ros/param_tree.h"

namespace hrg_gyro {

DriverSimRos::DriverSimRos(ros::NodeHandle nh, ros::NodeHandle pnh, bool owns_process)
    : nh_(nh), pnh_(pnh), params_(pnh, "driver_sim"), owns_process_(owns_process) {
  readScenario();
  readNodeParameters();
  advertise();
  announce();
  worker_ = std::thread(&DriverSimRos::run, this);
}

/// The scenario from the private parameters: a single gyro's, or a triad's.
void DriverSimRos::readScenario() {
  const YAML::Node params = privateParameters(pnh_);
  if (core::isTriadScenario(params)) {
    triad_config_ = std::make_unique<core::TriadSimulationConfig>(
        core::TriadSimulationConfig::parse(core::YamlField(params, ""), core::nodeOnlyScenarioKeys()));
    output_period_ = triad_config_->outputPeriod();
    start_time_ = triad_config_->start_time;
  } else {
    config_ = std::make_unique<core::SimulationConfig>(
        core::SimulationConfig::parse(core::YamlField(params, ""), core::nodeOnlyScenarioKeys()));
    output_period_ = config_->outputPeriod();
    start_time_ = config_->start_time;
  }
  // The scenario sections are the core parser's (it refuses unknown keys in them).
  params_.claim({"seed", "start_time", "resonator", "pickoff", "turntable", "generator", "thermal", "channels", "triad",
                 "dynamics"},
                true);
}

/// The node's own parameters (pace, clock, topics' queues), checked; unknown keys warned about.
void DriverSimRos::readNodeParameters() {
  time_scale_ = params_.get("time_scale", time_scale_);
  readClockPeriod();
  max_lag_ = params_.get("max_lag", max_lag_);
  frame_id_ = params_.get("frame_id", frame_id_);
  ros::param::param("/use_sim_time", use_sim_time_, false);
  readPublishClock();
  shutdown_when_done_ = params_.get("shutdown_when_done", shutdown_when_done_);
  wait_channels_ = params_.get("wait_for_subscribers/channels", 0);
  wait_turntable_ = params_.get("wait_for_subscribers/turntable", 0);
  wait_truth_ = params_.get("wait_for_subscribers/truth", 0);
  wait_timeout_ = params_.get("wait_timeout", wait_timeout_);
  pace_topic_ = params_.get<std::string>("pace_topic", pace_topic_);
  max_lead_ = params_.get("max_lead", max_lead_);
  pace_timeout_ = params_.get("pace_timeout", pace_timeout_);
  queue_size_ = params_.get("queue_size", 20000);
  params_.warnAboutUnknownKeys();
  if (!(clock_period_ > 0.0) || !std::isfinite(clock_period_)) {
    throw std::invalid_argument("~clock_period must be a positive number of seconds or auto");
  }
  if (use_sim_time_ && publish_clock_ && clock_period_ > output_period_ * (1.0 + 1e-9)) {
    ROS_WARN(
        "driver_sim: ~clock_period %g s is coarser than the output samples (%g s): timers of the nodes under "
        "sim time fire at most every %g s",
        clock_period_, output_period_, clock_period_);
  }
  if (!(max_lag_ > 0.0)) throw std::invalid_argument("~max_lag must be positive (s)");
  if (!(max_lead_ >= 0.0) || !std::isfinite(max_lead_)) throw std::invalid_argument("~max_lead must be >= 0 (s)");
  // Wall-clock stamps are due times, so a late thread catches up; under sim time the clock is ours.
  // Built here so that a bad ~time_scale is refused at start-up, not thrown in the worker thread.
  schedule_.emplace(time_scale_, use_sim_time_ ? max_lag_ : INFINITY);
  if (!use_sim_time_ && time_scale_ != 1.0) {
    ROS_WARN("driver_sim: ~time_scale = %g without /use_sim_time: stamps will run ahead of the wall clock",
             time_scale_);
  }
}

/// ~clock_period: a positive number of seconds, or auto.
void DriverSimRos::readClockPeriod() {
  // clock_period: "auto" (the template's value) or unset means: with every output sample, but no
  // more often than kFinestAutoClockPeriod. A consumer's timer under sim time fires only when /clock
  // passes its due time, so a clock coarser than the samples throttles it (a 50 Hz filter ran at
  // 20 Hz behind a 20 Hz clock); at the 10 kHz a bench gyro may run, a clock per sample would cost
  // every node of the graph a callback per sample for timers that no consumer runs that fast.
  const double auto_clock_period = std::max(output_period_, kFinestAutoClockPeriod);
  clock_period_ = auto_clock_period;
  XmlRpc::XmlRpcValue clock_raw;
  if (params_.getOptional("clock_period", &clock_raw)) {
    if (clock_raw.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      clock_period_ = static_cast<double>(clock_raw);
    } else if (clock_raw.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      clock_period_ = static_cast<int>(clock_raw);
    } else if (clock_raw.getType() != XmlRpc::XmlRpcValue::TypeString ||
               static_cast<std::string>(clock_raw) != "auto") {
      throw std::invalid_argument("~clock_period must be a positive number of seconds or auto");
    }
  }
}

/// ~publish_clock: true, false or auto.
void DriverSimRos::readPublishClock() {
  // publish_clock: "auto" (the template's value) or unset means: exactly when /use_sim_time is set.
  std::string publish_clock = "auto";
  XmlRpc::XmlRpcValue raw;
  if (params_.getOptional("publish_clock", &raw)) {
    if (raw.getType() == XmlRpc::XmlRpcValue::TypeBoolean) {
      publish_clock = static_cast<bool>(raw) ? "true" : "false";
    } else if (raw.getType() != XmlRpc::XmlRpcValue::TypeString || static_cast<std::string>(raw) != "auto") {
      throw std::invalid_argument("~publish_clock must be true, false or auto");
    }
  }
  publish_clock_ = publish_clock == "auto" ? use_sim_time_ : publish_clock == "true";
}

/// The topics: the table, each gyro's channels and truth (or the triad's), the precession loop's state,
/// the command and pace subscriptions, ~done and /clock.
void DriverSimRos::advertise() {
  turntable_pub_ = nh_.advertise<TurntableState>("turntable/state", queue_size_);
  if (triad_config_) {
    for (int i = 0; i < 3; ++i) {
      const std::string& axis = triad_config_->axes[i].name;
      axis_channels_pub_[i] = nh_.advertise<ChannelAmplitudes>(triadAxisTopic(axis, "channels"), queue_size_);
      axis_truth_pub_[i] = nh_.advertise<GroundTruth>(triadAxisTopic(axis, "truth"), queue_size_);
      if (triad_config_->axes[i].dynamics.averaged()) {
        axis_precession_pub_[i] = nh_.advertise<PrecessionState>(triadAxisTopic(axis, "precession/state"), queue_size_);
      }
    }
    fixture_pub_ = nh_.advertise<FixturePosition>("fixture/position", queue_size_);
    truth_pub_ = nh_.advertise<BodyTruth>("truth", queue_size_);
    if (triad_config_->accelerometer.enabled) {
      accelerometer_pub_ = nh_.advertise<sensor_msgs::Imu>("accel/data_raw", queue_size_);
    }
  } else {
    channels_pub_ = nh_.advertise<ChannelAmplitudes>("channels", queue_size_);
    truth_pub_ = nh_.advertise<GroundTruth>("truth", queue_size_);
    has_precession_loop_ = config_->dynamics.averaged();
    if (has_precession_loop_) precession_pub_ = nh_.advertise<PrecessionState>("precession/state", queue_size_);
  }
  // Subscribed either way: a command to a gyro without the loop is answered with a warning.
  command_sub_ = nh_.subscribe("command/precession", 10, &DriverSimRos::onPrecessionCommand, this);
  if (!pace_topic_.empty() && use_sim_time_) {
    pace_sub_ = nh_.subscribe<std_msgs::Time>(pace_topic_, 10, [this](const std_msgs::Time::ConstPtr& m) {
      paced_until_ = toNanoseconds(m->data);
      paced_wall_ = ros::WallTime::now().toSec();
    });
  } else if (!pace_topic_.empty()) {
    ROS_WARN("driver_sim: ~pace_topic '%s' ignored without /use_sim_time (real time waits for no one)",
             pace_topic_.c_str());
  }
  done_pub_ = pnh_.advertise<std_msgs::Bool>("done", 1, true);
  if (use_sim_time_ && publish_clock_) clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 100);
  std_msgs::Bool done;
  done.data = false;
  done_pub_.publish(done);
}

/// One line on what is simulated, at start-up.
void DriverSimRos::announce() {
  if (triad_config_) {
    ROS_INFO("driver_sim: %.1f s triad session (%zu fixture positions) at %.0f Hz output, time scale %s",
             triad_config_->duration(), triad_config_->positions.size(), 1.0 / output_period_,
             time_scale_ > 0.0 ? std::to_string(time_scale_).c_str() : "as fast as possible");
  } else {
    core::GyroSimulator probe(*config_);
    ROS_INFO("driver_sim: %.1f s scenario at %.0f Hz output (%s), time scale %s", probe.duration(),
             1.0 / output_period_, config_->generator.enabled ? "generator sweep first" : "turntable profile",
             time_scale_ > 0.0 ? std::to_string(time_scale_).c_str() : "as fast as possible");
  }
}

void DriverSimRos::onPrecessionCommand(const ros::MessageEvent<PrecessionCommand const>& event) {
  const PrecessionCommand::ConstPtr& msg = event.getMessage();
  if (!has_precession_loop_) {
    // Throttled on the wall clock: under sim time the clock may stand still or start near 0.
    const ros::WallTime now = ros::WallTime::now();
    ++ignored_commands_;
    if (ignored_commands_ == 1 || (now - last_ignored_warning_).toSec() >= 10.0) {
      last_ignored_warning_ = now;
      ROS_WARN(
          "driver_sim: precession command (%g rad/s) ignored (%llu so far): this scenario's gyro has no precession "
          "loop (its dynamics.model is not averaged; docs/simulation.md)",
          msg->rate, static_cast<unsigned long long>(ignored_commands_));
    }
    return;
  }
  if (!std::isfinite(msg->rate) || std::abs(msg->rate) > core::kMaxPrecessionRate) {
    ROS_WARN("driver_sim: precession command %g rad/s ignored: not a finite rate within +-%g rad/s", msg->rate,
             core::kMaxPrecessionRate);
    return;
  }
  std::lock_guard<std::mutex> lock(command_mutex_);
  pending_command_ = Command{msg->rate, event.getPublisherName()};
}

void DriverSimRos::takeCommand(core::GyroSimulator& sim) {
  std::optional<Command> command;
  {
    std::lock_guard<std::mutex> lock(command_mutex_);
    command.swap(pending_command_);
  }
  if (!command) return;
  sim.commandVirtualRate(command->rate);
  handed_source_ = command->publisher;
  ROS_INFO("driver_sim: precession at %g rad/s from %.3f s of the scenario, commanded by %s", command->rate,
           sim.elapsed(), command->publisher.c_str());
}

DriverSimRos::~DriverSimRos() {
  stop_ = true;
  if (worker_.joinable()) worker_.join();
}

std::uint32_t DriverSimRos::channelSubscribers() const {
  if (!triad_config_) return channels_pub_.getNumSubscribers();
  std::uint32_t fewest = axis_channels_pub_[0].getNumSubscribers();
  for (const ros::Publisher& p : axis_channels_pub_) fewest = std::min(fewest, p.getNumSubscribers());
  return fewest;
}

bool DriverSimRos::waitForSubscribers() {
  // wait_timeout <= 0: as long as it takes (a pipeline whose listeners are all part of the launch
  // must not lose its first samples because the host started them slowly); said every 10 s.
  const bool limited = wait_timeout_ > 0.0;
  const ros::WallTime start = ros::WallTime::now();
  ros::WallTime next_note = start + ros::WallDuration(10.0);
  while (!stop_ && ros::ok()) {
    if (static_cast<int>(channelSubscribers()) >= wait_channels_ &&
        static_cast<int>(turntable_pub_.getNumSubscribers()) >= wait_turntable_ &&
        static_cast<int>(truth_pub_.getNumSubscribers()) >= wait_truth_) {
      return true;
    }
    const ros::WallTime now = ros::WallTime::now();
    if (limited && (now - start).toSec() > wait_timeout_) {
      ROS_WARN(
          "driver_sim: starting after %.1f s without all expected subscribers (channels %u/%d, "
          "turntable %u/%d, truth %u/%d)",
          wait_timeout_, channelSubscribers(), wait_channels_, turntable_pub_.getNumSubscribers(), wait_turntable_,
          truth_pub_.getNumSubscribers(), wait_truth_);
      return true;
    }
    if (!limited && now > next_note) {
      next_note = now + ros::WallDuration(10.0);
      ROS_WARN("driver_sim: still waiting after %.0f s for subscribers (channels %u/%d, turntable %u/%d, truth %u/%d)",
               (now - start).toSec(), channelSubscribers(), wait_channels_, turntable_pub_.getNumSubscribers(),
               wait_turntable_, truth_pub_.getNumSubscribers(), wait_truth_);
    }
    ros::WallDuration(0.01).sleep();
  }
  return false;
}

bool DriverSimRos::waitForConsumer(core::Nanoseconds stamp) {
  const core::Nanoseconds lead = core::toNanoseconds(max_lead_);
  const double since = ros::WallTime::now().toSec();
  bool noted = false;
  while (!stop_ && ros::ok()) {
    if (pace_first_ == kNoPace) pace_first_ = stamp;
    // Before the consumer's first word: the lead from the first sample (it needs data to speak).
    const core::Nanoseconds until =
        paced_until_ == kNoPace ? pace_first_ : static_cast<core::Nanoseconds>(paced_until_);
    if (stamp <= until + lead) return true;
    if (pace_given_up_) return true;
    // Whichever came last, the start of this wait or the consumer's last word, the timeout counts from.
    const double now = ros::WallTime::now().toSec();
    const double quiet = now - std::max(since, static_cast<double>(paced_wall_));
    if (pace_timeout_ > 0.0 && quiet > pace_timeout_) {
      pace_given_up_ = true;
      ROS_WARN("driver_sim: nothing on ~pace_topic %s for %.0f s of wall time: going on without it",
               pace_sub_.getTopic().c_str(), quiet);
      return true;
    }
    if (!noted && now - since > 10.0) {
      noted = true;
      ROS_INFO("driver_sim: waiting for the consumer on %s (at %.3f s, this sample %.3f s)",
               pace_sub_.getTopic().c_str(), core::toSeconds(until), core::toSeconds(stamp));
    }
    ros::WallDuration(0.0005).sleep();
  }
  return false;
}

void DriverSimRos::publishSingle(const core::SimulationSample& s, const ros::Time& stamp, core::Nanoseconds origin) {
  // The sequence number is the sample's index, so a lost sample leaves a gap in it.
  auto channels = boost::make_shared<ChannelAmplitudes>(
      toChannelsMessage(s, stamp, static_cast<std::uint32_t>(s.index), frame_id_));
  if (s.channels_delivered) channels_pub_.publish(channels);
  // A record's sequence number is the controller's count, its stamp on the controller's clock.
  // (roscpp renumbers header.seq on a TCP connection; a nodelet in this process sees these.)
  for (const core::TurntableLogRecord& r : s.turntable) {
    turntable_pub_.publish(boost::make_shared<TurntableState>(toTurntableMessage(r, origin, frame_id_)));
  }
  if (truth_pub_.getNumSubscribers() > 0) {
    truth_pub_.publish(boost::make_shared<GroundTruth>(toTruthMessage(s, trueHeader(channels->header, stamp))));
  }
  if (has_precession_loop_) {
    updatePrecessionSource(s, handed_source_, &precession_source_);
    precession_pub_.publish(boost::make_shared<PrecessionState>(
        toPrecessionStateMessage(s, trueHeader(channels->header, stamp), precession_source_)));
  }
}

void DriverSimRos::publishTriad(const core::TriadSample& s, const ros::Time& stamp, core::Nanoseconds origin) {
  const core::TriadSimulationConfig& c = *triad_config_;
  for (int i = 0; i < 3; ++i) {
    const core::SimulationSample& axis = s.axes[i];
    auto channels = boost::make_shared<ChannelAmplitudes>(
        toChannelsMessage(axis, stamp, static_cast<std::uint32_t>(axis.index), c.axes[i].name));
    if (axis.channels_delivered) axis_channels_pub_[i].publish(channels);
    if (axis_truth_pub_[i].getNumSubscribers() > 0) {
      axis_truth_pub_[i].publish(
          boost::make_shared<GroundTruth>(toTruthMessage(axis, trueHeader(channels->header, stamp))));
    }
    if (c.axes[i].dynamics.averaged()) {
      // Its schedule's commands only: the state's source is the schedule's.
      axis_precession_pub_[i].publish(boost::make_shared<PrecessionState>(
          toPrecessionStateMessage(axis, trueHeader(channels->header, stamp), kScheduledPrecessionSource)));
    }
  }
  for (const core::TurntableLogRecord& r : s.turntable) {
    turntable_pub_.publish(boost::make_shared<TurntableState>(toTurntableMessage(r, origin, c.frame_id)));
  }
  if (s.fixture_logged)
    fixture_pub_.publish(boost::make_shared<FixturePosition>(toFixtureMessage(s, stamp, c.frame_id)));
  if (truth_pub_.getNumSubscribers() > 0) {
    truth_pub_.publish(boost::make_shared<BodyTruth>(toBodyTruthMessage(s, stamp, c.frame_id)));
  }
  if (s.accelerometer.present) {
    accelerometer_pub_.publish(boost::make_shared<sensor_msgs::Imu>(toAccelerometerMessage(s, stamp, c.accelerometer)));
  }
}

template <class Simulator, class Sample, class Publish>
void DriverSimRos::play(Simulator& sim, Sample* sample, const Publish& publish) {
  // Under sim time the clock must run before anyone waits for subscribers' time to pass.
  if (!clock_pub_.getTopic().empty()) {
    rosgraph_msgs::Clock c;
    c.clock = toRosTime(core::toNanoseconds(start_time_));
    clock_pub_.publish(c);
  }
  if (!waitForSubscribers()) return;
  // In wall time the stamps start now, after the wait, so they say when each sample was taken.
  const core::Nanoseconds origin =
      use_sim_time_ ? 0 : toNanoseconds(ros::Time::now()) - core::toNanoseconds(start_time_);
  const ros::WallTime wall_start = ros::WallTime::now();
  core::PlaybackSchedule& schedule = *schedule_;
  schedule.start(wall_start.toSec());
  Sample& s = *sample;
  double next_clock = 0.0;
  std::uint32_t seq = 0;
  // Under sim time with another source driving /clock (~publish_clock false: a second driver of the
  // same graph, a bag played with --clock), a sample goes out when /clock reaches its stamp: every
  // driver keeps that one clock's pace, so two drivers' stamps cannot drift apart by what the host
  // denied one of them (each pacing itself against the wall clock, a driver that was run late fell
  // behind the clock for good). While the clock stands still (its source not started yet, or done)
  // the driver goes on at its own ~time_scale, and waits again once the clock runs behind it.
  const bool follow_clock = use_sim_time_ && clock_pub_.getTopic().empty() && time_scale_ > 0.0;
  ClockWatch clock{ros::Time::now(), ros::WallTime::now()};
  std::uint64_t on_clock = 0;
  for (;;) {
    if (stop_ || !ros::ok()) break;
    takeCommand(sim);
    if (!sim.next(&s)) break;
    const ros::Time stamp = toRosTime(origin + s.stamp);
    const bool reached = follow_clock && waitForClock(stamp, sim.elapsed(), &clock);
    if (stop_ || !ros::ok()) break;
    on_clock += reached ? 1 : 0;
    if (!reached) keepSchedule(sim.elapsed());
    if (pace_sub_ && !waitForConsumer(origin + s.stamp)) break;
    if (!clock_pub_.getTopic().empty() && sim.elapsed() >= next_clock) {
      rosgraph_msgs::Clock c;
      c.clock = stamp;
      clock_pub_.publish(c);
      // Half a sample early: with the period equal to the samples' spacing, rounding of the
      // elapsed time must not skip every other sample.
      next_clock = sim.elapsed() + clock_period_ - 0.5 * output_period_;
    }
    publish(s, stamp, origin);
    ++seq;
  }
  if (stop_ || !ros::ok()) return;
  reportComplete(seq, sim.elapsed(), (ros::WallTime::now() - wall_start).toSec(), follow_clock, on_clock);
}

bool DriverSimRos::waitForClock(const ros::Time& stamp, double elapsed, ClockWatch* clock) {
  while (!stop_ && ros::ok()) {
    const ros::Time now = ros::Time::now();
    const ros::WallTime wall = ros::WallTime::now();
    if (now != clock->seen) {
      clock->seen = now;
      clock->moved = wall;
    }
    if (now >= stamp) {
      // This sample is due now: if the clock stops, the own schedule goes on from here.
      schedule_->start(wall.toSec() - elapsed / time_scale_);
      return true;
    }
    if ((wall - clock->moved).toSec() > kStillClock) return false;
    ros::WallDuration(0.0005).sleep();
  }
  return false;
}

void DriverSimRos::keepSchedule(double elapsed) {
  core::PlaybackSchedule& schedule = *schedule_;
  double late = 0.0;
  const double wait = schedule.waitFor(elapsed, ros::WallTime::now().toSec(), &late);
  if (wait > 0.0) {
    ros::WallDuration(wait).sleep();
  } else if (late > 0.1 && !use_sim_time_) {
    // The stamps still say when each sample was due (as a hardware clock would), so consumers
    // see the delay; this says where it came from.
    ROS_WARN_THROTTLE(10.0, "driver_sim: %.3f s behind schedule (this thread was not run in time); catching up", late);
  } else if (late > max_lag_ && use_sim_time_) {
    ROS_INFO_THROTTLE(30.0,
                      "driver_sim: %.3f s behind schedule: the simulated clock runs slower than "
                      "~time_scale (%.1f s let go so far)",
                      late, schedule.slid());
  }
}

void DriverSimRos::reportComplete(std::uint32_t seq, double elapsed, double wall, bool follow_clock,
                                  std::uint64_t on_clock) {
  const core::PlaybackSchedule& schedule = *schedule_;
  char lateness[128] = "";
  if (time_scale_ > 0.0 && !use_sim_time_) {
    std::snprintf(lateness, sizeof lateness, ", at most %.3f s behind schedule", schedule.maxLateness());
  } else if (follow_clock) {
    std::snprintf(lateness, sizeof lateness, ", %llu samples paced by /clock, the others by the schedule",
                  static_cast<unsigned long long>(on_clock));
  } else if (time_scale_ > 0.0) {
    std::snprintf(lateness, sizeof lateness, ", the schedule let go %.3f s in %llu pauses", schedule.slid(),
                  static_cast<unsigned long long>(schedule.slides()));
  }
  ROS_INFO("driver_sim: scenario complete: %u samples, %.1f s simulated in %.1f s of wall time (%.1fx)%s", seq, elapsed,
           wall, wall > 0 ? elapsed / wall : 0.0, lateness);
  std_msgs::Bool done;
  done.data = true;
  done_pub_.publish(done);
  if (shutdown_when_done_ && owns_process_) {
    ros::WallDuration(0.5).sleep();  // let the last messages and the latched flag go out
    ros::requestShutdown();
  }
}

void DriverSimRos::run() {
  if (triad_config_) {
    core::TriadSimulator sim(*triad_config_);
    core::TriadSample s;
    play(sim, &s, [this](const core::TriadSample& x, const ros::Time& stamp, core::Nanoseconds origin) {
      publishTriad(x, stamp, origin);
    });
  } else {
    core::GyroSimulator sim(*config_);
    core::SimulationSample s;
    play(sim, &s, [this](const core::SimulationSample& x, const ros::Time& stamp, core::Nanoseconds origin) {
      publishSingle(x, stamp, origin);
    });
  }
}

}  // namespace hrg_gyro
