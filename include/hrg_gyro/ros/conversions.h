// Conversions between the core's types and ROS time and messages.
#pragma once

#include <ros/time.h>
#include <sensor_msgs/Imu.h>

#include <string>
#include <vector>

#include "hrg_gyro/AlignmentResult.h"
#include "hrg_gyro/BodyTruth.h"
#include "hrg_gyro/CalibrationResult.h"
#include "hrg_gyro/ChannelAmplitudes.h"
#include "hrg_gyro/FixturePosition.h"
#include "hrg_gyro/GroundTruth.h"
#include "hrg_gyro/GyroOutput.h"
#include "hrg_gyro/PrecessionCommand.h"
#include "hrg_gyro/PrecessionState.h"
#include "hrg_gyro/TriadCalibrationResult.h"
#include "hrg_gyro/TriadOutput.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/WaveState.h"
#include "hrg_gyro/core/alignment/attitude_hold.h"
#include "hrg_gyro/core/alignment/gyrocompass.h"
#include "hrg_gyro/core/calibration/calibration_outcome.h"
#include "hrg_gyro/core/calibration/triad/triad_calibration.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/processing/gyro_processor.h"
#include "hrg_gyro/core/processing/triad_combiner.h"
#include "hrg_gyro/core/simulation/gyro_simulator.h"
#include "hrg_gyro/core/simulation/triad_simulator.h"

namespace hrg_gyro {

inline core::Nanoseconds toNanoseconds(const ros::Time& t) {
  return static_cast<core::Nanoseconds>(t.sec) * 1000000000LL + static_cast<core::Nanoseconds>(t.nsec);
}

/// The channel message's header with the sample's true stamp (a scheduled glitch moves the channel
/// message's stamp only): for the truth and the precession state that go with the sample.
inline std_msgs::Header trueHeader(std_msgs::Header header, const ros::Time& stamp) {
  header.stamp = stamp;
  return header;
}

inline ros::Time toRosTime(core::Nanoseconds ns) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(ns < 0 ? 0 : ns));
  return t;
}

// The messages of one processed sample. The processor node and `hrg_bag process` both build their
// output with these, so the offline tool gives the node's numbers bit for bit.
core::ChannelSample fromMessage(const ChannelAmplitudes& msg);
WaveState toWaveMessage(const ChannelAmplitudes& input, const core::WaveState& wave, const std::string& frame_id);
GyroOutput toOutputMessage(const std_msgs::Header& header, const core::ProcessorResult& result);

// The triad: an axis's output as the combiner takes it, and a triad sample as TriadOutput and as
// sensor_msgs/Imu (REP-145: orientation and acceleration not measured, covariance[0] = -1; the
// full 3x3 angular velocity covariance). The triad node and `hrg_bag process --triad` both use
// these, so the offline tool gives the node's messages bit for bit.
core::AxisOutput toAxisOutput(const GyroOutput& msg);
TriadOutput toTriadOutputMessage(const core::TriadBodySample& sample, const std::string& frame_id);
sensor_msgs::Imu toImuMessage(const core::TriadBodySample& sample, const std::string& frame_id);

// The messages of one simulated sample (driver_sim and `hrg_bag simulate`).
ChannelAmplitudes toChannelsMessage(const core::SimulationSample& s, const ros::Time& stamp, std::uint32_t seq,
                                    const std::string& frame_id);
/// A turntable record as the simulated table controller logged it: header.seq its record count (a lost record leaves a
/// gap), the stamp on the controller's clock; `origin` shifts the stamp (wall-clock playback), a zero stamp stays 0.
TurntableState toTurntableMessage(const core::TurntableLogRecord& r, core::Nanoseconds origin,
                                  const std::string& frame_id);
GroundTruth toTruthMessage(const core::SimulationSample& s, const std_msgs::Header& header);
/// The name PrecessionState.source gives the scenario's own schedule (dynamics.commands).
extern const char* const kScheduledPrecessionSource;
/// Who commanded the rate in force once `s`'s commands are taken up: each command applied in its window
/// replaces *source, by kScheduledPrecessionSource for the schedule's and by `commander` (the node
/// that published it) for one taken from command/precession.
void updatePrecessionSource(const core::SimulationSample& s, const std::string& commander, std::string* source);
/// The precession loop's state at a sample (averaged resonator): stamped with the sample; `source`
/// who commanded the rate in force.
PrecessionState toPrecessionStateMessage(const core::SimulationSample& s, const std_msgs::Header& header,
                                         const std::string& source);
/// A command the loop took up, as the commanding node would have issued it (`hrg_bag simulate` writes
/// the scenario's schedule so); stamped at `stamp`.
PrecessionCommand toPrecessionCommandMessage(const core::AppliedPrecession& command, const ros::Time& stamp,
                                             const std::string& frame_id);

// The messages of one simulated triad sample (driver_sim and `hrg_bag simulate` on a triad scenario):
// the fixture's position (fixture/position) and the body's truth (truth), stamped with the sample,
// frame_id the triad's body frame; header.seq the sample's index.
FixturePosition toFixtureMessage(const core::TriadSample& s, const ros::Time& stamp, const std::string& frame_id);
BodyTruth toBodyTruthMessage(const core::TriadSample& s, const ros::Time& stamp, const std::string& frame_id);
/// The simulated accelerometer's sample (accel/data_raw): sensor_msgs/Imu with linear_acceleration
/// (REP-145: +g up at rest) and its covariance (the white noise's variance on the diagonal),
/// orientation and angular velocity not measured (covariance[0] = -1), frame_id the accelerometer's.
sensor_msgs::Imu toAccelerometerMessage(const core::TriadSample& s, const ros::Time& stamp,
                                        const core::TriadAccelerometerConfig& accelerometer);
/// The topic (relative) of one axis's stream of a triad: "<axis>/<stream>", e.g. "x/channels".
inline std::string triadAxisTopic(const std::string& axis, const std::string& stream) { return axis + "/" + stream; }

HarmonicEstimate toMessage(const core::HarmonicFitResult& fit, double frequency);
core::HarmonicFitResult fromMessage(const HarmonicEstimate& msg);

/// The calibration's gates as messages (single-axis and triad results alike).
std::vector<QualityGate> toMessages(const std::vector<core::GateResult>& gates);
/// The outcome as a message; `written` and `file` say what happened to the parameter file.
CalibrationResult toMessage(const core::CalibrationOutcome& outcome, bool written, const std::string& file,
                            const ros::Time& stamp);
/// The parts of an outcome a message carries (for summaries built from a received result).
core::CalibrationOutcome fromMessage(const CalibrationResult& msg);

/// A triad calibration's outcome as its result message: the body frame (header.frame_id), the axes,
/// M, A = M^-1 and the bias with their standard errors, each axis's verdict, the gates, the notes and
/// the outcome's reason. The run's stamp, files, what was written and reloaded (and why not, in
/// `reason`) and its duration are the calibrator's to set.
TriadCalibrationResult toMessage(const core::TriadOutcome& outcome);

/// The fixture's position as logged, its quaternion as is: core::acceptFixtureOrientation decides
/// whether it is a rotation (the live calibrator and `hrg_bag calibrate --method triad` alike).
core::FixtureRecord fromMessage(const FixturePosition& msg);

// North-finding: the records the gyrocompass node (and `hrg_bag align`) feed core::Gyrocompass with,
// and its outputs. Frames and signs: core/alignment/local_level.h.
/// A triad sample as the combiner made it (missing_axes, which the message does not carry, left 0).
core::TriadBodySample fromMessage(const TriadOutput& msg);
/// The indexer's (or rate table's) state.
core::IndexerRecord fromMessage(const TurntableState& msg);
/// An accelerometer's specific force (linear_acceleration, REP-145: +g up at rest), in its own frame.
core::AccelerometerRecord fromAccelerometerMessage(const sensor_msgs::Imu& msg);
/// Any IMU's message as the gyrocompass's IMU input reads it (REP-145: a covariance of all 0 or with
/// [0] = -1 is not given; linear_acceleration_covariance[0] = -1: no acceleration).
core::ImuSample fromImuMessage(const sensor_msgs::Imu& msg);
/// The driver's precession state.
core::PrecessionStateRecord fromMessage(const PrecessionState& msg);
/// The result as a message: stamped with the window's end; frame_id the frame its triad or gyro
/// publishes in.
AlignmentResult toMessage(const core::AlignmentResult& result, const std::string& frame_id);
/// An accepted result as an absolute attitude for a navigation filter: the body's orientation
/// (body -> ENU at the window's end) with its ENU covariance; angular velocity and acceleration not
/// measured (covariance[0] = -1). Stamped with the window's end.
sensor_msgs::Imu toAlignmentImuMessage(const core::AlignmentResult& result, const std::string& frame_id);
/// The held attitude at a triad sample: the hold's orientation and covariance, the sample's angular
/// velocity and covariance (as toImuMessage gives them), acceleration not measured.
sensor_msgs::Imu toHeldImuMessage(const core::AttitudeHold& hold, const core::TriadBodySample& sample,
                                  const std::string& frame_id);

}  // namespace hrg_gyro
