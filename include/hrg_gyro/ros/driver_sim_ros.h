// ROS wrapper of the simulated gyro on its turntable (node driver_sim, nodelet hrg_gyro/DriverSim).
//
// Reads the scenario from the private parameters (the keys of config/scenarios/*.yaml, loaded with
// `rosparam load` into ~), runs core::GyroSimulator in a worker thread and publishes, per output
// sample: `channels` (ChannelAmplitudes), `turntable/state` (TurntableState) and `truth`
// (GroundTruth). With /use_sim_time it also drives /clock, `~time_scale` times faster than real
// time (a lag beyond `~max_lag` slows the simulated clock instead of being chased, see
// core::PlaybackSchedule), or, when another source drives /clock (`~publish_clock` false), follows
// that clock: a sample goes out when /clock reaches its stamp; without it, stamps follow the wall
// clock from the start and a late
// thread catches up. `~done` (std_msgs/Bool, latched)
// turns true when the scenario is over.
//
// A triad scenario (a `triad` section: core::TriadSimulationConfig) runs core::TriadSimulator instead
// and publishes, per output sample, `<axis>/channels` and `<axis>/truth` for each of its three axes
// (frame_id the axis's name), `turntable/state`, `fixture/position` (hrg_gyro/FixturePosition, on a
// change of position or lock and every second) and `truth` (hrg_gyro/BodyTruth), the last two with
// the triad's frame_id (its triad.frame_id; ~frame_id is the single gyro's). With
// `triad/accelerometer` enabled it also publishes `accel/data_raw` (sensor_msgs/Imu, REP-145: the
// specific force of gravity, +g up at rest, with its covariance; its own frame_id) with every sample.
// An axis run by the averaged resonator (triad/axes[i]/dynamics, model: averaged) follows its
// schedule (dynamics/commands) and publishes `<axis>/precession/state` with every sample, `source`
// "schedule" (a triad's axes take no commands on a topic).
//
// A gyro with a precession loop (dynamics.model: averaged, core::DynamicsConfig) also takes commands
// of its virtual rotation on `command/precession` (hrg_gyro/PrecessionCommand), executed from the
// next carrier period as its electronics would, beside the scenario's own schedule, and publishes what
// the loop executes on `precession/state` (hrg_gyro/PrecessionState) with every sample, `source` the
// node that published the command in force (its caller id as this driver saw it; "schedule" for the
// scenario's own). A command to a gyro without the loop is ignored with a warning naming why.
#pragma once

#include <ros/ros.h>

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "hrg_gyro/PrecessionCommand.h"
#include "hrg_gyro/core/simulation/gyro_simulator.h"
#include "hrg_gyro/core/simulation/playback_schedule.h"
#include "hrg_gyro/core/simulation/triad_simulator.h"
#include "hrg_gyro/ros/parameter_reader.h"

namespace hrg_gyro {

class DriverSimRos {
 public:
  /// Throws std::exception (with the offending key named) when the parameters are invalid.
  DriverSimRos(ros::NodeHandle nh, ros::NodeHandle pnh, bool owns_process);
  ~DriverSimRos();

  /// The private parameters as read at start-up (unknown and defaulted keys).
  const ParameterReader& parameters() const { return params_; }

 private:
  // The constructor's steps, in order.
  void readScenario();
  void readNodeParameters();
  void readClockPeriod();
  void readPublishClock();
  void advertise();
  void announce();
  void run();
  /// Plays `sim` (a GyroSimulator or a TriadSimulator) on the schedule; `publish(sample, stamp,
  /// origin)` publishes one sample's messages.
  template <class Simulator, class Sample, class Publish>
  void play(Simulator& sim, Sample* sample, const Publish& publish);
  /// When another source drives /clock: the clock last seen and when (wall time) it last moved.
  struct ClockWatch {
    ros::Time seen;
    ros::WallTime moved;
  };
  /// Waits until /clock reaches `stamp` (true; the schedule restarted from there, `elapsed` s of
  /// simulation in) or stands still for kStillClock s (false: the own schedule goes on).
  bool waitForClock(const ros::Time& stamp, double elapsed, ClockWatch* clock);
  /// Sleeps until the sample `elapsed` s in is due on the schedule; says so when running behind.
  void keepSchedule(double elapsed);
  /// The "scenario complete" line and ~done; shuts the process down when asked to.
  void reportComplete(std::uint32_t seq, double elapsed, double wall, bool follow_clock, std::uint64_t on_clock);
  void publishSingle(const core::SimulationSample& s, const ros::Time& stamp, core::Nanoseconds origin);
  void publishTriad(const core::TriadSample& s, const ros::Time& stamp, core::Nanoseconds origin);
  bool waitForSubscribers();
  void onPrecessionCommand(const ros::MessageEvent<PrecessionCommand const>& event);
  /// Hands the last command received to the simulator (worker thread, before each sample).
  void takeCommand(core::GyroSimulator& sim);
  void takeCommand(core::TriadSimulator&) {}
  /// The fewest subscribers of the channels: of the one topic, or of the triad's three axes.
  std::uint32_t channelSubscribers() const;

  ros::NodeHandle nh_, pnh_;
  ParameterReader params_;
  bool owns_process_;                               // a node may shut itself down when done; a nodelet must not
  std::unique_ptr<core::SimulationConfig> config_;  // a single gyro's scenario, or
  std::unique_ptr<core::TriadSimulationConfig> triad_config_;  // a triad's
  double output_period_ = 0.0;                                 // s, of either
  double start_time_ = 0.0;                                    // s, of either
  ros::Publisher channels_pub_, turntable_pub_, truth_pub_, clock_pub_, done_pub_;
  std::array<ros::Publisher, 3> axis_channels_pub_, axis_truth_pub_;  // a triad's; truth_pub_ its body truth
  ros::Publisher fixture_pub_;
  ros::Publisher accelerometer_pub_;                   // a triad's accelerometer, when its scenario has one
  ros::Publisher precession_pub_;                      // a gyro with a precession loop only
  std::array<ros::Publisher, 3> axis_precession_pub_;  // a triad's axes with a precession loop only
  ros::Subscriber command_sub_;
  // ~pace_topic (sim time only): a consumer's std_msgs/Time saying up to which stamp it has taken
  // the data in; a sample more than ~max_lead past it waits (a calibrator fitting, or reloading the
  // processor, holds the session instead of letting it run on). After ~pace_timeout s of wall time
  // without a word from it, the driver goes on without it (<= 0: never).
  std::string pace_topic_;
  double max_lead_ = 1.0;       // s of stamps
  double pace_timeout_ = 60.0;  // s of wall time
  ros::Subscriber pace_sub_;
  static constexpr core::Nanoseconds kNoPace = INT64_MIN;
  std::atomic<core::Nanoseconds> paced_until_{kNoPace};
  std::atomic<double> paced_wall_{0.0};
  bool pace_given_up_ = false;              // worker thread only
  core::Nanoseconds pace_first_ = kNoPace;  // the first sample's stamp (worker thread only)
  /// Waits until the consumer on ~pace_topic has taken the data in up to `stamp` - ~max_lead; false
  /// when stopping.
  bool waitForConsumer(core::Nanoseconds stamp);
  std::mutex command_mutex_;
  struct Command {
    double rate;
    std::string publisher;  // the caller id of the node that published it
  };
  std::optional<Command> pending_command_;  // under command_mutex_: received, not yet taken up
  std::string handed_source_;               // worker thread: the publisher of the last command handed over
  std::string precession_source_;           // worker thread: who commanded the rate in force
  bool has_precession_loop_ = false;
  std::uint64_t ignored_commands_ = 0;  // commands to a gyro without the loop (callback thread only)
  ros::WallTime last_ignored_warning_;
  double time_scale_ = 1.0;
  double max_lag_ = 0.25;                           // s, sim time only
  std::optional<core::PlaybackSchedule> schedule_;  // built (and validated) with the parameters
  // Sim time between /clock messages: every subscriber of /clock (every node under sim time) pays
  // for each, and every timer under sim time waits for one.
  double clock_period_ = 0.0;
  static constexpr double kFinestAutoClockPeriod = 1e-3;  // s: "auto" publishes at most 1 kHz
  // s of wall time a /clock driven by another source may stand still before this driver, following
  // it, goes on at its own time_scale (the source not started yet, or done)
  static constexpr double kStillClock = 2.0;
  std::string frame_id_ = "gyro_link";
  bool use_sim_time_ = false;
  bool publish_clock_ = true;
  bool shutdown_when_done_ = false;
  int wait_channels_ = 0, wait_turntable_ = 0, wait_truth_ = 0;
  int queue_size_ = 20000;  // ~queue_size of every topic it publishes
  double wait_timeout_ = 10.0;
  std::atomic<bool> stop_{false};
  std::thread worker_;
};

}  // namespace hrg_gyro
