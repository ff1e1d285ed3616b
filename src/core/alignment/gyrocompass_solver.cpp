#include "hrg_gyro/core/alignment/gyrocompass_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hrg_gyro/core/alignment/motion_gate.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/processing/block_mean_stillness.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kMaxPitch = 1.4;  // rad: the body's x within 10 deg of vertical has no heading
constexpr double kDegrees = 180.0 / kPi;

Eigen::Matrix3d rotZ(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

Eigen::Matrix3d skewOf(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Linear interpolation of a value between records at stamps (seconds from the window's start); false
// when `t` is not between two records at most `max_gap` apart.
bool interpolate(const std::vector<double>& times, const std::vector<double>& values, double t, double max_gap,
                 double* out) {
  if (times.empty() || t < times.front() || t > times.back()) return false;
  const auto it = std::lower_bound(times.begin(), times.end(), t);
  const std::size_t k = static_cast<std::size_t>(it - times.begin());
  if (times[k] == t) {
    *out = values[k];
    return true;
  }
  const double t0 = times[k - 1], t1 = times[k];
  if (t1 - t0 > max_gap) return false;
  *out = values[k - 1] + (values[k] - values[k - 1]) * (t - t0) / (t1 - t0);
  return true;
}

// The integrals of cos(psi) and sin(psi) over an interval along which psi moves linearly from a to b.
void integrateCosSin(double a, double b, double dt, double* c, double* s) {
  const double middle = 0.5 * (a + b), k = dt * sinc(0.5 * (b - a));
  *c = k * std::cos(middle);
  *s = k * std::sin(middle);
}

// A channel's regressors at time t in the indexed mode: its direction d turned by the indexer, integrated
// (the integrals of cos psi and sin psi so far), and t for its bias.
void indexedPoint(const Eigen::Vector3d& d, double cos_integral, double sin_integral, double t, double* point) {
  point[0] = d.x() * cos_integral - d.y() * sin_integral;
  point[1] = d.x() * sin_integral + d.y() * cos_integral;
  point[2] = t;
}

// An axis's regressors at time t in the sweep mode: t, the commanded angle and its gain harmonics.
const double* sweepPoint(double t, double angle, const std::vector<int>& orders, std::vector<double>* x) {
  (*x)[0] = t;
  (*x)[1] = angle;
  for (std::size_t o = 0; o < orders.size(); ++o) {
    (*x)[2 + 2 * o] = std::sin(orders[o] * angle);
    (*x)[3 + 2 * o] = std::cos(orders[o] * angle);
  }
  return x->data();
}

// The residual drift harmonics' rate integrals over a sample: orders 2 and 4 of the wave angle, which
// the commanded angle moves (the wave's own offset only turns the pair), added to `sum`.
void addDriftProbes(double psi_a, double psi_b, double dt, std::array<double, 4>* sum) {
  double c2, s2, c4, s4;
  integrateCosSin(2.0 * psi_a, 2.0 * psi_b, dt, &c2, &s2);
  integrateCosSin(4.0 * psi_a, 4.0 * psi_b, dt, &c4, &s4);
  (*sum)[0] += c2;
  (*sum)[1] += s2;
  (*sum)[2] += c4;
  (*sum)[3] += s4;
}

}  // namespace

bool GyrocompassSolver::buildStatic() {
  const GyroStreamRecords& st = w_.streams[0];
  parameters_ = 3;
  series_.assign(3, AngleSeries());
  for (std::size_t c = 0; c < 3; ++c) {
    series_[c].columns = {static_cast<int>(c)};
    series_[c].regressors.assign(1, {});
  }
  BlockMeanStillness motion(3, s_.motion.block);
  std::array<double, 3> y{{0.0, 0.0, 0.0}};
  int seg = -1;
  double last_time = -INFINITY;
  bool broken = true;
  for (std::size_t k = 0; k < st.stamp.size(); ++k) {
    const double t_end = seconds(st.stamp[k]), t_start = std::max(t_end - st.dt[k], last_time);
    if (excludedSample(t_start, t_end)) {  // around a step of the base: left out, the rest after it new
      broken = true;
      continue;
    }
    // In the first rest's frame: the base's steps before this sample turned back.
    const Eigen::Vector3d turned = carriedRotation(t_end) * Eigen::Map<const Eigen::Vector3d>(&st.increment[3 * k]);
    const double* inc = turned.data();
    if (broken || st.broken[k]) {
      broken = false;
      seg = static_cast<int>(segments_.size());
      segments_.push_back(Segment());
      segments_.back().start = t_start;
      segments_.back().group = seg;
      y = {{0.0, 0.0, 0.0}};
      for (std::size_t c = 0; c < 3; ++c) series_[c].push(t_start, seg, 0.0, &t_start);
      motion.restart();
    }
    for (std::size_t c = 0; c < 3; ++c) {
      y[c] += inc[c];
      series_[c].push(t_end, seg, y[c], &t_end);
    }
    segments_.back().end = t_end;
    motion.add(st.dt[k], inc);
    used_seconds_ += st.dt[k];
    ++samples_;
    last_time = t_end;
  }
  worst_motion_ = motion.worstHalfSpread();
  return true;
}

bool GyrocompassSolver::prepareIndexer() {
  const auto& records = w_.indexer;
  if (records.size() < 2) return refuse("input", "no indexer records in the window (addIndexer)");
  for (const IndexerRecord& r : records) {
    indexer_time_.push_back(seconds(r.stamp));
    indexer_angle_.push_back(r.angle);
  }
  const std::size_t n = records.size();
  indexer_rate_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (std::isfinite(records[k].rate)) {
      indexer_rate_[k] = records[k].rate;
    } else {
      const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < n ? k + 1 : n - 1;
      indexer_rate_[k] = (indexer_angle_[b] - indexer_angle_[a]) / (indexer_time_[b] - indexer_time_[a]);
    }
  }
  if (s_.indexer.continuous) return true;
  // Rests: runs of records at rest, no two further apart than max_record_gap.
  const IndexerSettings& x = s_.indexer;
  for (std::size_t k = 0; k < n;) {
    if (std::abs(indexer_rate_[k]) >= x.rest_rate) {
      ++k;
      continue;
    }
    std::size_t e = k;
    double low = indexer_angle_[k], high = low, sum = 0.0;
    while (e < n && std::abs(indexer_rate_[e]) < x.rest_rate &&
           (e == k || indexer_time_[e] - indexer_time_[e - 1] <= x.max_record_gap)) {
      low = std::min(low, indexer_angle_[e]);
      high = std::max(high, indexer_angle_[e]);
      sum += indexer_angle_[e];
      ++e;
    }
    Rest rest;
    rest.from = indexer_time_[k] + x.settle;
    rest.to = indexer_time_[e - 1];
    rest.angle = sum / static_cast<double>(e - k);
    if (rest.to > rest.from) {
      const std::string wandered = indexerWanderProblem(high - low, rest.angle, x.position_tolerance);
      if (!wandered.empty()) return refuse(kMotionGate, wandered);
      rests_.push_back(rest);
    }
    k = e;
  }
  if (rests_.empty()) return refuse("input", "the indexer never rested in the window (indexer/rest_rate, settle)");
  return true;
}

bool GyrocompassSolver::indexerAt(double t, double* angle) const {
  return interpolate(indexer_time_, indexer_angle_, t, s_.indexer.max_record_gap, angle);
}

bool GyrocompassSolver::buildIndexed() {
  if (!prepareIndexer()) return false;
  const GyroStreamRecords& st = w_.streams[0];
  const std::size_t channels = st.channels;
  const IndexerSettings& x = s_.indexer;
  const std::vector<Eigen::Vector3d> direction = indexedDirections(channels);
  parameters_ = 2 + channels;
  series_.assign(channels, AngleSeries());
  for (std::size_t c = 0; c < channels; ++c) {
    series_[c].columns = {0, 1, static_cast<int>(2 + c)};
    series_[c].regressors.assign(3, {});
  }
  // The horizontal information, per channel: the spread of its direction turned by the indexer.
  std::vector<Eigen::Vector2d> s1(channels, Eigen::Vector2d::Zero());
  std::vector<Eigen::Matrix2d> s2(channels, Eigen::Matrix2d::Zero());
  double cos_integral = 0.0, sin_integral = 0.0, weight = 0.0;
  std::array<double, 3> y{{0.0, 0.0, 0.0}};
  BlockMeanStillness motion(channels, s_.motion.block);
  int seg = -1, current_rest = -1;
  bool continues = false;
  double last_time = -INFINITY;
  for (std::size_t k = 0; k < st.stamp.size(); ++k) {
    const double t_b = seconds(st.stamp[k]), t_a = std::max(t_b - st.dt[k], last_time);
    double psi_a, psi_b;
    int rest = -1;
    if (excludedSample(t_a, t_b) || !indexerSpan(t_a, t_b, &rest, &psi_a, &psi_b)) {
      continues = false;
      continue;
    }
    const double* raw = &st.increment[channels * k];
    double inc[3];
    for (std::size_t c = 0; c < channels; ++c) {
      inc[c] = raw[c] - (x.continuous ? direction[c].z() * (psi_b - psi_a) : 0.0);
    }
    double dc, ds;
    integrateCosSin(psi_a, psi_b, t_b - t_a, &dc, &ds);
    if (!continues || st.broken[k] || rest != current_rest) {
      seg = static_cast<int>(segments_.size());
      Segment g;
      g.start = t_a;
      g.group = x.continuous ? 0 : rest;
      segments_.push_back(g);
      y = {{0.0, 0.0, 0.0}};
      for (std::size_t c = 0; c < channels; ++c) {
        double point[3];
        indexedPoint(direction[c], cos_integral, sin_integral, t_a, point);
        series_[c].push(t_a, seg, 0.0, point);
      }
      motion.restart();
      current_rest = rest;
    }
    cos_integral += dc;
    sin_integral += ds;
    for (std::size_t c = 0; c < channels; ++c) {
      const Eigen::Vector3d& d = direction[c];
      y[c] += inc[c];
      double point[3];
      indexedPoint(d, cos_integral, sin_integral, t_b, point);
      series_[c].push(t_b, seg, y[c], point);
      const Eigen::Vector2d u(d.x() * dc - d.y() * ds, d.x() * ds + d.y() * dc);  // integral of its turned direction
      s1[c] += u;
      s2[c] += u * u.transpose() / (t_b - t_a);
    }
    weight += t_b - t_a;
    Segment& g = segments_.back();
    g.end = t_b;
    g.angle = std::isfinite(g.angle) ? g.angle : 0.5 * (psi_a + psi_b);
    motion.add(t_b - t_a, inc);
    used_seconds_ += t_b - t_a;
    ++samples_;
    last_time = t_b;
    continues = true;
  }
  worst_motion_ = motion.worstHalfSpread();
  if (samples_ < 10) {
    return refuse("input", x.continuous ? "no gyro samples within the indexer's records"
                                        : "no gyro samples while the indexer rested (indexer/settle, rest_rate)");
  }
  return indexedDesignResolvesHeading(s1, s2, weight);
}

std::vector<Eigen::Vector3d> GyrocompassSolver::indexedDirections(std::size_t channels) const {
  const IndexerSettings& x = s_.indexer;
  std::vector<Eigen::Vector3d> direction(channels);
  for (std::size_t c = 0; c < channels; ++c) {
    direction[c] = s_.single_gyro ? x.gyro_axis : Eigen::Vector3d(x.body_to_platform.col(c));
  }
  return direction;
}

bool GyrocompassSolver::indexerSpan(double t_a, double t_b, int* rest, double* psi_a, double* psi_b) const {
  if (s_.indexer.continuous) return indexerAt(t_a, psi_a) && indexerAt(t_b, psi_b);
  for (std::size_t r = 0; r < rests_.size() && *rest < 0; ++r) {
    if (t_a >= rests_[r].from && t_b <= rests_[r].to) *rest = static_cast<int>(r);
  }
  if (*rest < 0) return false;
  *psi_a = *psi_b = rests_[*rest].angle;
  return true;
}

bool GyrocompassSolver::indexedDesignResolvesHeading(const std::vector<Eigen::Vector2d>& s1,
                                                     const std::vector<Eigen::Matrix2d>& s2, double weight) {
  const IndexerSettings& x = s_.indexer;
  const std::size_t channels = s1.size();
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
  for (std::size_t c = 0; c < channels; ++c) information += s2[c] - s1[c] * s1[c].transpose() / weight;
  information /= weight;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(information);
  const double small = eigen.eigenvalues()(0), large = eigen.eigenvalues()(1);
  std::string angles;
  for (const Rest& r : rests_) angles += (angles.empty() ? "" : ", ") + formatNumbers("%.1f", r.angle * kDegrees);
  if (!(large > 1e-6)) {
    return refuse("design", x.continuous || rests_.size() > 1
                                ? "the indexer's turning shows the gyros no horizontal component of the Earth's "
                                  "rate: no sensitive axis is horizontal"
                                : "one indexer position (" + angles +
                                      " deg) cannot tell the gyros' biases from the Earth's rate: use two "
                                      "positions or more, or the static mode");
  }
  if (small < 1e-3 * large) {
    return refuse("design",
                  std::string(s_.single_gyro ? "one gyro" : "the gyros") + " at the positions " + angles +
                      " deg sense one horizontal component of the Earth's rate only: the heading is ambiguous "
                      "(two mirror solutions); use four positions 90 deg apart, continuous rotation, or the "
                      "triad's two horizontal axes");
  }
  return true;
}

bool GyrocompassSolver::buildSweep() {
  const std::size_t per_axis = 2 + 2 * s_.sweep.gain_orders.size();
  parameters_ = 3 * per_axis;
  series_.assign(3, AngleSeries());
  for (std::size_t axis = 0; axis < 3; ++axis) {
    AngleSeries& out = series_[axis];
    for (std::size_t k = 0; k < per_axis; ++k) out.columns.push_back(static_cast<int>(axis * per_axis + k));
    out.regressors.assign(per_axis, {});
    if (w_.precession[axis].size() < 2) {
      return refuse("input", formatNumbers("no precession state for axis %.0f in the window (addPrecession)", axis));
    }
    if (!buildSweepAxis(axis, per_axis)) return false;
  }
  return true;
}

bool GyrocompassSolver::buildSweepAxis(std::size_t axis, std::size_t per_axis) {
  const SweepSettings& sw = s_.sweep;
  const GyroStreamRecords& st = w_.streams[axis];
  AngleSeries& out = series_[axis];
  std::vector<double> x(per_axis);
  std::vector<double> times, psi, change_time, change_rate;
  commandTrack(w_.precession[axis], &times, &psi, &change_time, &change_rate);
  BlockMeanStillness motion(1, s_.motion.block);
  double y = 0.0, turned_up = 0.0, turned_down = 0.0, last_time = -INFINITY;
  int seg = -1, command = -1;
  bool continues = false;
  for (auto& probe : sweep_probes_[axis]) probe.clear();
  std::array<double, 4> probe_sum{{0.0, 0.0, 0.0, 0.0}};
  auto pushProbes = [&]() {
    for (std::size_t p = 0; p < 4; ++p) sweep_probes_[axis][p].push_back(probe_sum[p]);
  };
  std::uint64_t used = 0;
  for (std::size_t k = 0; k < st.stamp.size(); ++k) {
    const double t_b = seconds(st.stamp[k]), t_a = std::max(t_b - st.dt[k], last_time);
    double psi_a, psi_b;
    const int m =
        static_cast<int>(std::upper_bound(change_time.begin(), change_time.end(), t_b) - change_time.begin()) - 1;
    const bool usable = m >= 0 && t_a >= change_time[m] + sw.settle &&
                        interpolate(times, psi, t_a, s_.indexer.max_record_gap, &psi_a) &&
                        interpolate(times, psi, t_b, s_.indexer.max_record_gap, &psi_b);
    if (!usable) {
      continues = false;
      continue;
    }
    if (!continues || st.broken[k] || m != command) {
      seg = static_cast<int>(segments_.size());
      Segment g;
      g.channel = static_cast<int>(axis);
      g.start = t_a;
      g.rate = change_rate[m];
      g.group = seg;
      segments_.push_back(g);
      y = 0.0;
      out.push(t_a, seg, 0.0, sweepPoint(t_a, psi_a, sw.gain_orders, &x));
      pushProbes();
      motion.restart();
      command = m;
    }
    y += st.increment[k];
    out.push(t_b, seg, y, sweepPoint(t_b, psi_b, sw.gain_orders, &x));
    addDriftProbes(psi_a, psi_b, t_b - t_a, &probe_sum);
    pushProbes();
    (psi_b > psi_a ? turned_up : turned_down) += std::abs(psi_b - psi_a);
    segments_.back().end = t_b;
    motion.add(t_b - t_a, &st.increment[k]);
    if (axis == 0) used_seconds_ += t_b - t_a;
    ++used;
    last_time = t_b;
    continues = true;
  }
  worst_motion_ = std::max(worst_motion_, motion.worstHalfSpread());
  if (used < 10) return refuse("input", formatNumbers("axis %.0f: no outputs within its precession state", axis));
  if (axis == 0) samples_ = used;
  return sweptBothWays(axis, turned_up, turned_down);
}

void GyrocompassSolver::commandTrack(const std::vector<PrecessionStateRecord>& records, std::vector<double>* times,
                                     std::vector<double>* psi, std::vector<double>* change_time,
                                     std::vector<double>* change_rate) const {
  // The commanded angle at each record's stamp (the record carries it at its sample's centre and
  // the rate in force at its end), and the times the commanded rate changed.
  for (std::size_t k = 0; k < records.size(); ++k) {
    const double t = seconds(records[k].stamp);
    const double half = k == 0 ? 0.0 : 0.5 * (t - times->back());
    times->push_back(t);
    psi->push_back(records[k].angle + records[k].rate * half);
    if (k == 0 || records[k].rate != records[k - 1].rate) {
      change_time->push_back(k == 0 ? t : (*times)[k - 1]);
      change_rate->push_back(records[k].rate);
    }
  }
}

bool GyrocompassSolver::sweptBothWays(std::size_t axis, double turned_up, double turned_down) {
  const SweepSettings& sw = s_.sweep;
  if (std::min(turned_up, turned_down) < sw.min_turns * kTwoPi) {
    return refuse("design",
                  formatNumbers("axis %.0f: the commanded angle turned %.2f turns up and %.2f down in the data "
                                "used; the sweep needs at least %.2f each way (sweep/min_turns)",
                                axis, turned_up / kTwoPi, turned_down / kTwoPi, sw.min_turns));
  }
  if (std::abs(turned_up - turned_down) > 0.05 * kTwoPi) {
    result_.notes.push_back(formatNumbers("axis %.0f: %.2f turns up, %.2f down: unequal sweeps leave part of D(theta)",
                                          axis, turned_up / kTwoPi, turned_down / kTwoPi));
  }
  return true;
}

bool GyrocompassSolver::level(LevelMeasurement* out) {
  const LevelSettings& l = s_.level;
  if (l.source == LevelSource::kDeclared) {
    out->roll = l.roll;
    out->pitch = l.pitch;
    out->covariance = Eigen::Vector2d(l.roll_sigma * l.roll_sigma, l.pitch_sigma * l.pitch_sigma).asDiagonal();
    return true;
  }
  const Eigen::Matrix3d mount = l.accelerometer_to_body.normalized().toRotationMatrix();
  const bool indexed = s_.mode == AlignmentMode::kIndexed;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), previous = Eigen::Vector3d::Zero();
  Eigen::Matrix3d differences = Eigen::Matrix3d::Zero(), transfer = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d mounting = Eigen::Matrix3d::Zero();  // d f_frame / d (the mounting's error, accelerometer axes)
  std::size_t n = 0, pairs = 0;
  int previous_group = -2;
  for (const AccelerometerRecord& r : w_.accelerometer) {
    if (r.stamp < w_.start || r.stamp > w_.end) continue;
    const double t = seconds(r.stamp);
    if (excludedSample(t, t)) continue;
    Eigen::Matrix3d to_frame = indexed ? mount : Eigen::Matrix3d(carriedRotation(t) * mount);
    int group = 0;
    if (indexed) {
      double psi = NAN;
      group = -1;
      if (s_.indexer.continuous) {
        if (indexerAt(t, &psi)) group = 0;
      } else {
        for (std::size_t k = 0; k < rests_.size() && group < 0; ++k) {
          if (t >= rests_[k].from && t <= rests_[k].to) {
            group = static_cast<int>(k);
            psi = rests_[k].angle;
          }
        }
      }
      if (group < 0) continue;
      to_frame = rotZ(psi) * s_.indexer.body_to_platform * mount;
    }
    const Eigen::Vector3d f = to_frame * r.specific_force;
    if (group == previous_group) {
      const Eigen::Vector3d d = f - previous;
      differences += d * d.transpose();
      ++pairs;
    }
    previous = f;
    previous_group = group;
    sum += f;
    transfer += to_frame;
    mounting -= to_frame * skewOf(r.specific_force);
    ++n;
  }
  if (n < 10 || pairs < 2) {
    return refuse("level", indexed ? "too few accelerometer samples while the indexer rested (addAccelerometer)"
                                   : "too few accelerometer samples in the window (addAccelerometer)");
  }
  const Eigen::Vector3d mean = sum / static_cast<double>(n);
  transfer /= static_cast<double>(n);
  result_.accelerometer_gravity = mean.norm();
  if (std::abs(mean.norm() / kStandardGravity - 1.0) > l.max_gravity_error) {
    return refuse("level", formatNumbers("the accelerometer's mean specific force is %.4g m/s^2, not gravity (%.5g, "
                                         "level/max_gravity_error %.3g): a wrong unit, frame or a moving base",
                                         mean.norm(), kStandardGravity, l.max_gravity_error));
  }
  // White noise from successive differences (blind to a slow change), the mean's; the bias through
  // the rotations it was seen in (an indexer's positions average its horizontal part away).
  const Eigen::Matrix3d noise = differences / (2.0 * static_cast<double>(pairs));
  mounting /= static_cast<double>(n);
  const double bias2 = l.accelerometer_bias_sigma * l.accelerometer_bias_sigma;
  const double mount2 = l.accelerometer_mounting_sigma * l.accelerometer_mounting_sigma;
  const Eigen::Matrix3d covariance = noise / static_cast<double>(n) + bias2 * transfer * transfer.transpose() +
                                     mount2 * mounting * mounting.transpose();
  const EulerAngles a = levelFromSpecificForce(mean);
  const Eigen::Matrix<double, 2, 3> j = levelJacobian(mean);
  out->roll = a.roll;
  out->pitch = a.pitch;
  out->covariance = j * covariance * j.transpose();
  return true;
}

bool GyrocompassSolver::measure(const IntegratedAngleFit& fit, const LevelMeasurement& level, EarthRateMeasurement* m) {
  const AngleFitResult& f = fit.result();
  const GyroNoiseModel& noise = s_.noise;
  const double bias2 = noise.residual_bias * noise.residual_bias;
  const double harmonics2 = noise.residual_drift_harmonics * noise.residual_drift_harmonics;
  // L: the parameters -> the Earth's rate in the frame (3 x q); the body-bias transfer.
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(3, parameters_);
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  Eigen::Matrix3d bias_transfer = Eigen::Matrix3d::Zero();
  const std::size_t channels = fit.channels().size();
  if (s_.mode == AlignmentMode::kStatic) {
    l.setIdentity();
  } else if (s_.mode == AlignmentMode::kIndexed) {
    // The biases absorb the component along the platform's z; it is the one that makes the levelled
    // vertical the Earth's, v: (L w)_z = v. (Taking v itself for it would leave tilt x tilt x h.)
    const Eigen::Matrix3d level_rotation = levelRotation(level.roll, level.pitch);
    l(0, 0) = l(1, 1) = 1.0;
    l(2, 0) = -level_rotation(2, 0) / level_rotation(2, 2);
    l(2, 1) = -level_rotation(2, 1) / level_rotation(2, 2);
    offset.z() = verticalEarthRate(s_.latitude) / level_rotation(2, 2);
  } else {
    const std::size_t per_axis = parameters_ / 3;
    for (int i = 0; i < 3; ++i) l.col(i * per_axis) = triad_matrix_.col(i);
    offset = -w_.triad.bias;
  }
  const Eigen::VectorXd beta = f.parameters;
  m->rate = l * beta + offset;
  m->white = l * f.white * l.transpose();
  m->angle_random_walk = l * f.angle_random_walk * l.transpose();
  m->rate_random_walk = l * f.rate_random_walk * l.transpose();
  // A constant rate per channel: the calibration's bias (and D at a resting wave).
  Eigen::MatrixXd per_channel(3, channels);
  for (std::size_t c = 0; c < channels; ++c) per_channel.col(c) = l * f.constant_rate[c];
  if (s_.mode == AlignmentMode::kSweep) {
    // A body bias b reaches the axes as A b (A = M^-1), then the fit and M.
    bias_transfer = per_channel * w_.triad.bodyToAxis();
  } else if (channels == 3) {
    bias_transfer = per_channel;  // the channels are the body axes
  }
  const Eigen::MatrixXd constant = channels == 3 ? Eigen::MatrixXd(bias_transfer) : per_channel;
  m->residual_bias = bias2 * constant * constant.transpose();
  m->bias_transfer = bias_transfer;
  if (s_.mode != AlignmentMode::kSweep) {
    // At rest each wave's D(theta) residual is one more constant rate (indexed: cancelled with the bias).
    m->drift_harmonics = harmonics2 * constant * constant.transpose();
  } else {
    // A harmonic of random phase and rms sigma_h: sigma_h^2 (J_c J_c^T + J_s J_s^T), the larger order.
    for (std::size_t axis = 0; axis < 3; ++axis) {
      Eigen::Matrix3d best = Eigen::Matrix3d::Zero();
      for (int order = 0; order < 2; ++order) {
        const Eigen::Vector3d jc = l * fit.response(axis, sweep_probes_[axis][2 * order]);
        const Eigen::Vector3d js = l * fit.response(axis, sweep_probes_[axis][2 * order + 1]);
        const Eigen::Matrix3d p = harmonics2 * (jc * jc.transpose() + js * js.transpose());
        if (p.trace() > best.trace()) best = p;
      }
      m->drift_harmonics += best;
    }
  }
  // The indexer: each position's angle off by a small angle e moves that position's regressors by
  // e (-X_y w_x + X_x w_y) (their angle, in the cumulative form the fit takes).
  if (s_.mode == AlignmentMode::kIndexed && s_.indexer.angle_sigma > 0.0) {
    int groups = 0;
    for (const Segment& g : segments_) groups = std::max(groups, g.group + 1);
    for (int group = 0; group < groups; ++group) {
      Eigen::VectorXd response = Eigen::VectorXd::Zero(parameters_);
      for (std::size_t c = 0; c < channels; ++c) {
        const AngleSeries& series = fit.channels()[c];
        std::vector<double> probe(series.size(), 0.0);
        for (std::size_t i = 0; i < series.size(); ++i) {
          if (segments_[series.segment[i]].group != group) continue;
          probe[i] = -series.regressors[1][i] * beta(0) + series.regressors[0][i] * beta(1);
        }
        response += fit.response(c, probe);
      }
      const Eigen::Vector3d j = l * response;
      m->indexer += s_.indexer.angle_sigma * s_.indexer.angle_sigma * j * j.transpose();
    }
  }
  return true;
}

void GyrocompassSolver::summariseSegments(const AngleFitResult& f) {
  for (std::size_t id = 0; id < segments_.size(); ++id) {
    const Segment& g = segments_[id];
    AlignmentSegment out;
    out.channel = g.channel;
    out.start = g.start;
    out.end = g.end;
    out.indexer_angle = s_.mode == AlignmentMode::kIndexed ? g.angle : NAN;
    out.commanded_rate = g.rate;
    for (const SegmentResidual& r : f.segments) {
      if (r.segment != static_cast<std::int32_t>(id)) continue;
      if (g.channel >= 0 && r.channel != static_cast<std::size_t>(g.channel)) continue;
      out.residual_rate.push_back(r.residual_rate);
      out.residual_rate_std.push_back(r.residual_rate_std);
      out.rms.push_back(r.rms);
      out.predicted_rms.push_back(r.predicted_rms);
    }
    result_.segments.push_back(out);
  }
}

AlignmentResult GyrocompassSolver::solve() {
  AlignmentResult& r = result_;
  r.mode = s_.mode;
  r.single_gyro = s_.single_gyro;
  r.frame = s_.mode == AlignmentMode::kIndexed ? "indexer" : "body";
  r.start = w_.start;
  r.end = w_.end;
  r.last_sample = std::max(r.last_sample, w_.lastSample());
  r.budget.latitude = s_.latitude;
  r.budget.max_latitude = s_.max_latitude;
  r.budget.horizontal_earth_rate = horizontalEarthRate(s_.latitude);
  r.noise_sources = s_.noise_sources.summary();
  if (!w_.refused_gate.empty()) {
    refuse(w_.refused_gate, w_.refused_reason);
    return r;
  }
  if (!w_.started) {
    refuse("input", "no gyro samples");
    return r;
  }
  if (!allanRateMatches()) return r;
  triad_matrix_ = w_.triad.axis_to_body;
  HeadingSolution still;
  if (!solveStill(&still)) return r;  // refused by what no estimator changes: input, design, level
  const InertialFrameResult tracked = canTrack() ? track() : InertialFrameResult();
  if (!chooseAndAnswer(still, tracked) || !gateAttitude()) return r;
  r.accepted = true;
  r.reason = r.summary();
  return r;
}

bool GyrocompassSolver::allanRateMatches() {
  const std::vector<double>& dt = w_.streams[0].dt;
  if (s_.allan_tau0 <= 0.0 || dt.empty()) return true;
  std::vector<double> sorted = dt;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double period = sorted[sorted.size() / 2];
  if (std::abs(period / s_.allan_tau0 - 1.0) <= 0.02) return true;
  return refuse("noise", formatNumbers("the window's samples are %.6g s apart, the Allan file's (tau0) %.6g "
                                       "s: its white angle noise Q is per sample of another rate; measure "
                                       "it at this stream's rate (hrg_bag allan)",
                                       period, s_.allan_tau0));
}

void GyrocompassSolver::describeHoldStart(const HeadingSolution& h) {
  AlignmentResult& r = result_;
  // For a hold: the bias the triad carries at rest, and its covariance with the attitude error.
  const double bias2 = s_.noise.residual_bias * s_.noise.residual_bias;
  const double harmonics2 = s_.noise.residual_drift_harmonics * s_.noise.residual_drift_harmonics;
  r.bias_variance = bias2 + harmonics2;
  r.attitude_bias_covariance = h.bias_to_attitude * (s_.mode == AlignmentMode::kSweep ? bias2 : bias2 + harmonics2);
  // Where the triad's body is at the window's end.
  r.body_orientation = r.orientation;
  if (s_.mode == AlignmentMode::kIndexed) {
    double psi = indexer_angle_.back();
    indexerAt(seconds(w_.streams[0].last), &psi);
    const Eigen::Matrix3d body = r.orientation.toRotationMatrix() * rotZ(psi) *
                                 (s_.single_gyro ? Eigen::Matrix3d::Identity() : s_.indexer.body_to_platform);
    r.body_orientation = Eigen::Quaterniond(body).normalized();
    r.notes.push_back(formatNumbers("indexed: %.0f segments; the gyros' own bias cancels", segments_.size()));
  }
}

bool GyrocompassSolver::applyStillGates(const HeadingSolution& h) {
  AlignmentResult& r = result_;
  const double hh = r.budget.horizontal_earth_rate;
  const double mismatch = std::abs(h.horizontal_rate - hh);
  if (mismatch > std::max(s_.max_earth_rate_error * hh, 4.0 * h.horizontal_rate_std)) {
    return refuse("earth_rate",
                  formatNumbers("the horizontal rate measured, %.4g rad/s, is not the Earth's %.4g rad/s at "
                                "latitude %.3f deg (max_earth_rate_error %.2f): a bias far beyond the "
                                "calibration's, a wrong latitude or a turning base",
                                h.horizontal_rate, hh, s_.latitude * kDegrees, s_.max_earth_rate_error));
  }
  return checkEarth(still_rate_, still_level_);
}

bool GyrocompassSolver::checkEarth(const EarthRateMeasurement& m, const LevelMeasurement& level) {
  // The up direction in the measured frame, from its level; the indexed mode imposes the vertical part.
  const Eigen::Vector3d up = levelRotation(level.roll, level.pitch).transpose() * Eigen::Vector3d::UnitZ();
  result_.earth_checks =
      checkAgainstTheEarth(m.rate, m.covariance(), up, upCovarianceFromLevel(level.roll, level.pitch, level.covariance),
                           s_.latitude, s_.max_earth_sigmas, s_.mode != AlignmentMode::kIndexed);
  const std::optional<EarthCheck> failed = firstFailed(result_.earth_checks);
  return failed ? refuse("earth_check", failed->describe()) : true;
}

bool GyrocompassSolver::gateAttitude() {
  if (std::abs(result_.attitude.pitch) <= kMaxPitch) return true;
  return refuse("attitude",
                formatNumbers("pitch %.1f deg: the frame's x axis is within %.0f deg of vertical and has no heading",
                              result_.attitude.pitch * kDegrees, 90.0 - kMaxPitch * kDegrees));
}

}  // namespace core
}  // namespace hrg_gyro
