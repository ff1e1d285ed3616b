// The gyrocompass solver's tracking estimator (the body tracked by the gyros, gravity followed in the
// inertial frame: inertial_frame_alignment.h) and the choice between it and the still-base fit
// (gyrocompass_solver.h).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/alignment/gyrocompass_solver.h"
#include "hrg_gyro/core/common/number_format.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kDegrees = 180.0 / kPi;
constexpr double kComparisonFloor = 1e-6;  // rad

Eigen::Matrix3d rotZ(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

// The yaw variance of an ENU small-rotation covariance at an attitude, rad^2.
double yawVariance(const EulerAngles& a, const Eigen::Matrix3d& enu) {
  return std::max(eulerCovarianceFromEnu(a, enu)(2, 2), 0.0);
}

}  // namespace

bool GyrocompassSolver::canTrack() const {
  return s_.estimator != EstimatorChoice::kStillBase && !s_.single_gyro && s_.mode != AlignmentMode::kSweep &&
         s_.level.source == LevelSource::kAccelerometer && w_.accelerometer.size() >= 100;
}

InertialFrameResult GyrocompassSolver::track() {
  const GyroStreamRecords& st = w_.streams[0];
  // The unbroken stretch of samples that ends the window: the body's turn over a gap is unknown.
  std::size_t first = 0;
  for (std::size_t k = 0; k < st.stamp.size(); ++k) {
    if (st.broken[k]) first = k;
  }
  InertialFrameResult none;
  if (st.stamp.size() < first + 100) {
    none.problem = "too few unbroken triad samples at the window's end";
    return none;
  }
  BodyAttitudeTrack body(seconds(st.stamp[first]) - st.dt[first]);
  for (std::size_t k = first; k < st.stamp.size(); ++k) {
    body.add(seconds(st.stamp[k]), st.dt[k], Eigen::Map<const Eigen::Vector3d>(&st.increment[3 * k]));
  }
  InertialFrameInput in;
  in.latitude = s_.latitude;
  const Eigen::Matrix3d mount = s_.level.accelerometer_to_body.normalized().toRotationMatrix();
  for (const AccelerometerRecord& r : w_.accelerometer) {
    const double t = seconds(r.stamp);
    if (t <= body.start() || t > body.end()) continue;
    in.accel_time.push_back(t);
    in.accel_force.push_back(mount * r.specific_force);
  }
  in.gyro_bias = s_.noise.residual_bias;
  in.gyro_drift_harmonics = s_.noise.residual_drift_harmonics;
  in.gyro_rate_random_walk = s_.noise.rate_random_walk;
  in.gyro_angle_random_walk = s_.noise.angle_random_walk;
  in.accel_bias = s_.level.accelerometer_bias_sigma;
  in.accel_mounting = s_.level.accelerometer_mounting_sigma;
  InertialFrameResult out = alignInInertialFrame(body, in);
  // For the checks against the Earth: the gyros' mean rate over the stretch (b0), in the same result.
  out.up_start = out.start_to_enu.transpose().col(2);
  mean_rate_ = body.meanRate();
  return out;
}

bool GyrocompassSolver::chooseAndAnswer(const HeadingSolution& still, const InertialFrameResult& tracked) {
  AlignmentResult& r = result_;
  const auto problem = stillBaseProblem();
  if (tracked.ok) {
    // The two headings of the same frame at the window's end; their shared biases cancel in the difference.
    const Eigen::Matrix3d still_end = still.orientation.toRotationMatrix() * carriedRotation(INFINITY);
    EulerAngles a = eulerFromOrientation(Eigen::Quaterniond(still_end));
    Eigen::Matrix3d tracked_frame = tracked.end_to_enu;
    if (s_.mode == AlignmentMode::kIndexed) tracked_frame = tracked_frame * trackedFrameFromBody().transpose();
    const EulerAngles t = eulerFromOrientation(Eigen::Quaterniond(tracked_frame));
    // Below a microradian the two are not compared (noiseless sessions: their discretisations differ there).
    const double sigma = std::sqrt(still.budget.noise * still.budget.noise + yawVariance(t, tracked.budget.noise) +
                                   kComparisonFloor * kComparisonFloor);
    r.tracking_heading = trueHeadingDegrees(t.yaw);
    r.tracking_heading_sigma = std::sqrt(yawVariance(t, tracked.budget.total())) * kDegrees;
    r.estimator_difference = wrapToPi(a.yaw - t.yaw) / sigma;
  }
  if (s_.estimator == EstimatorChoice::kTracking) {
    if (!tracked.ok) {
      return refuse("tracking",
                    tracked.problem.empty()
                        ? std::string("estimator tracking needs the triad and an accelerometer (level/source "
                                      "accelerometer), in the static or indexed mode")
                        : tracked.problem);
    }
    return answerFromTracking(tracked, "asked for (estimator: tracking)");
  }
  if (!problem.first.empty()) {
    if (tracked.ok) return answerFromTracking(tracked, "the base was not still: " + problem.second);
    const bool could = s_.estimator == EstimatorChoice::kAuto && !s_.single_gyro && s_.mode != AlignmentMode::kSweep;
    return refuse(problem.first,
                  problem.second + (could && s_.level.source != LevelSource::kAccelerometer
                                        ? "; with an accelerometer (level/source accelerometer) the tracking "
                                          "estimator follows a moving base"
                                        : (could && !tracked.problem.empty() ? "; tracking: " + tracked.problem : "")));
  }
  if (tracked.ok && std::abs(r.estimator_difference) > s_.max_estimator_sigmas) {
    return answerFromTracking(
        tracked, formatNumbers("the still-base fit and the tracking differ by %.1f standard errors of their "
                               "noise (max_estimator_sigmas %.1f): the base moved in a way the gyros alone "
                               "cannot tell from the Earth's rate (a slow lean)",
                               r.estimator_difference, s_.max_estimator_sigmas));
  }
  return answerFromStill(still, steps_.empty() ? "the base was still: the still-base fit is the most precise"
                                               : "the base was still between its steps, carried");
}

Eigen::Matrix3d GyrocompassSolver::trackedFrameFromBody() const {
  // Indexed: the body sits on the platform turned by the indexer's angle at the window's end.
  double psi = indexer_angle_.empty() ? 0.0 : indexer_angle_.back();
  indexerAt(seconds(w_.streams[0].last), &psi);
  return rotZ(psi) * s_.indexer.body_to_platform;  // body -> the indexer's zero frame
}

bool GyrocompassSolver::answerFromTracking(const InertialFrameResult& t, const std::string& why) {
  AlignmentResult& r = result_;
  r.estimator = "tracking";
  r.estimator_reason = why;
  Eigen::Matrix3d frame = t.end_to_enu;
  if (s_.mode == AlignmentMode::kIndexed) frame = frame * trackedFrameFromBody().transpose();
  r.orientation = Eigen::Quaterniond(frame).normalized();
  r.attitude = eulerFromOrientation(r.orientation);
  r.body_orientation = Eigen::Quaterniond(t.end_to_enu).normalized();
  r.covariance_enu = t.budget.total();
  r.covariance_rpy = eulerCovarianceFromEnu(r.attitude, r.covariance_enu);
  HeadingErrorBudget& b = r.budget;
  auto sigma = [&](const Eigen::Matrix3d& p) { return std::sqrt(yawVariance(r.attitude, p)); };
  b.white_angle_noise = b.angle_random_walk = 0.0;
  b.noise = sigma(t.budget.noise);
  b.residual_bias = sigma(t.budget.residual_bias);
  b.drift_harmonics = sigma(t.budget.drift_harmonics);
  b.bias_random_walk = sigma(t.budget.bias_random_walk);
  b.level = sigma(t.budget.level);
  b.indexer = 0.0;
  b.total = std::sqrt(std::max(r.covariance_rpy(2, 2), 0.0));
  r.heading = trueHeadingDegrees(r.attitude.yaw);
  r.heading_sigma = b.total * kDegrees;
  const double bias2 = s_.noise.residual_bias * s_.noise.residual_bias;
  const double harmonics2 = s_.noise.residual_drift_harmonics * s_.noise.residual_drift_harmonics;
  r.bias_variance = bias2 + harmonics2;
  r.attitude_bias_covariance = t.bias_to_attitude * (bias2 + harmonics2);
  r.velocity_white = t.velocity_white;
  r.velocity_random_walk = t.velocity_random_walk;
  r.accelerometer_gravity = t.gravity;
  r.levelled_rate = Eigen::Vector3d::Constant(NAN);
  r.horizontal_rate = r.horizontal_rate_std = NAN;
  // The noise is measured from these residuals: only a gross misfit shows, twice max_scatter.
  if (t.scatter > 2.0 * s_.motion.max_scatter) {
    return refuse("stillness", formatNumbers("tracking: the velocity residuals scatter %.2f times the noise "
                                             "measured (limit twice motion/max_scatter, %.2f): the base "
                                             "travels, or the accelerometer is not on the gyros' body",
                                             t.scatter, 2.0 * s_.motion.max_scatter));
  }
  return checkEarthTracked(t);
}

bool GyrocompassSolver::checkEarthTracked(const InertialFrameResult& t) {
  // The indexed body turns on its platform: its mean rate is not the Earth's alone.
  if (s_.mode != AlignmentMode::kStatic) return true;
  const double length = t.seconds;
  const GyroNoiseModel& n = s_.noise;
  // The gyros' mean rate over the stretch: the bias, its walks, the angle noise at both ends, and the
  // base's net turn over the stretch (bounded by what the still-base fit's residuals show).
  double base = 0.0;
  for (std::size_t c = 0; fit_ && c < fit_->channels().size(); ++c) {
    double squares = 0.0;
    const std::vector<double> e = fit_->residuals(c);
    for (double v : e) squares += v * v;
    base = std::max(base, std::sqrt(2.0 * squares / std::max<double>(e.size(), 1.0)));
  }
  const double white = result_.white_noise.empty() ? 0.0 : result_.white_noise.front();
  const double rate_variance = n.residual_bias * n.residual_bias +
                               n.residual_drift_harmonics * n.residual_drift_harmonics +
                               n.rate_random_walk * n.rate_random_walk * length / 3.0 +
                               1.2 * n.angle_random_walk * n.angle_random_walk / length +
                               (2.0 * white * white + base * base) / (length * length);
  const double tilt = s_.level.accelerometer_bias_sigma / kStandardGravity;
  const double tilt_variance =
      tilt * tilt + s_.level.accelerometer_mounting_sigma * s_.level.accelerometer_mounting_sigma;
  const Eigen::Vector3d up = t.up_start;
  result_.earth_checks = checkAgainstTheEarth(mean_rate_, rate_variance * Eigen::Matrix3d::Identity(), up,
                                              tilt_variance * (Eigen::Matrix3d::Identity() - up * up.transpose()),
                                              s_.latitude, s_.max_earth_sigmas, true);
  const std::optional<EarthCheck> failed = firstFailed(result_.earth_checks);
  return failed ? refuse("earth_check", failed->describe()) : true;
}

}  // namespace core
}  // namespace hrg_gyro
