#include "hrg_gyro/core/alignment/inertial_frame_alignment.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/alignment/integrated_angle_fit.h"
#include "hrg_gyro/core/alignment/local_level.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/allan_deviation.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kPointSpacing = 0.1;  // s between the fine fit's points
constexpr int kGaussNewtonSteps = 2;
constexpr double kTurnForAccelerometerBias = 0.3;  // rad the body turns before the accelerometer's bias is fitted

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// The velocities at the fit's points, V_b0 and V_n0, and V_b0's response to each budget source.
struct VelocityPoints {
  std::vector<double> time;
  std::vector<Eigen::Vector3d> body, reference;
  std::vector<Eigen::Matrix3d> by_gyro_bias, by_accel_bias, by_mounting;
  Eigen::Vector3d force_sum = Eigen::Vector3d::Zero();
  std::size_t records = 0;
};

double medianSpacing(const std::vector<double>& t) {
  std::vector<double> d;
  for (std::size_t i = 1; i < t.size(); ++i) d.push_back(t[i] - t[i - 1]);
  if (d.empty()) return NAN;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

VelocityPoints integrateVelocities(const BodyAttitudeTrack& track, const InertialFrameInput& in) {
  VelocityPoints p;
  const Eigen::Vector3d u(0.0, std::cos(in.latitude), std::sin(in.latitude));
  const Eigen::Vector3d up_force(0.0, 0.0, kStandardGravity);
  const double period = medianSpacing(in.accel_time);
  const std::size_t stride = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(kPointSpacing / period)));
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Matrix3d gyro = Eigen::Matrix3d::Zero(), accel = Eigen::Matrix3d::Zero(), mount = Eigen::Matrix3d::Zero();
  // Each record is the specific force at its stamp, turned by the attitude at that stamp (at rest in
  // the local level the product is gravity in b0 whatever the body does: the two must be paired in
  // time); the velocity is its trapezoid from the first record on, as are the responses.
  struct Terms {
    Eigen::Vector3d f0;
    Eigen::Matrix3d gyro, accel, mount;
  } last{};
  double previous = NAN, origin = NAN;
  std::size_t since_point = 0;
  for (std::size_t j = 0; j < in.accel_time.size(); ++j) {
    const double t = in.accel_time[j] - track.start();
    if (t < 0.0 || t > track.end() - track.start()) continue;
    const double at = track.start() + t;
    const Eigen::Matrix3d c = track.attitudeAt(at);
    const Eigen::Vector3d& f = in.accel_force[j];
    const Terms now{c * f, -skew(c * f) * track.biasResponseAt(at), c, -c * skew(f)};
    const double interval = t - previous;
    previous = t;
    // Across a gap in the records too: at rest f_b0 is gravity turning smoothly with the Earth.
    if (!std::isfinite(origin)) {
      origin = t;
      last = now;
      continue;
    }
    if (!(interval > 0.0)) continue;
    v += 0.5 * (last.f0 + now.f0) * interval;
    gyro += 0.5 * (last.gyro + now.gyro) * interval;
    accel += 0.5 * (last.accel + now.accel) * interval;
    mount += 0.5 * (last.mount + now.mount) * interval;
    last = now;
    p.force_sum += f;
    ++p.records;
    if (++since_point < stride) continue;
    since_point = 0;
    // n0 is ENU at the track's start: the reference from the first record's interval on.
    p.time.push_back(t - origin);
    p.body.push_back(v);
    p.reference.push_back(turningGravityIntegral(u, up_force, t) - turningGravityIntegral(u, up_force, origin));
    p.by_gyro_bias.push_back(gyro);
    p.by_accel_bias.push_back(accel);
    p.by_mounting.push_back(mount);
  }
  return p;
}

// Least-squares a t + b t^2 through the points (no intercept: both start at zero).
void quadraticFit(const std::vector<double>& t, const std::vector<Eigen::Vector3d>& v, Eigen::Vector3d* a,
                  Eigen::Vector3d* b) {
  Eigen::Matrix2d n = Eigen::Matrix2d::Zero();
  Eigen::Matrix<double, 2, 3> r = Eigen::Matrix<double, 2, 3>::Zero();
  for (std::size_t i = 0; i < t.size(); ++i) {
    const Eigen::Vector2d x(t[i], t[i] * t[i]);
    n += x * x.transpose();
    r += x * v[i].transpose();
  }
  const Eigen::Matrix<double, 2, 3> c = n.ldlt().solve(r);
  *a = c.row(0).transpose();
  *b = c.row(1).transpose();
}

// TRIAD on the gravity direction and that of its turn; false when the turn is not seen.
bool coarseAlignment(const VelocityPoints& p, Eigen::Matrix3d* c0) {
  Eigen::Vector3d ab, bb, an, bn;
  quadraticFit(p.time, p.body, &ab, &bb);
  quadraticFit(p.time, p.reference, &an, &bn);
  auto triad = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, Eigen::Matrix3d* m) {
    const Eigen::Vector3d e1 = a.normalized(), across = a.cross(b);
    if (!(across.norm() > 1e-12 * a.norm() * b.norm()) || !(a.norm() > 0.0)) return false;
    const Eigen::Vector3d e2 = across.normalized();
    m->col(0) = e1;
    m->col(1) = e2;
    m->col(2) = e1.cross(e2);
    return true;
  };
  Eigen::Matrix3d mb, mn;
  if (!triad(ab, bb, &mb) || !triad(an, bn, &mn)) return false;
  *c0 = mn * mb.transpose();
  return c0->allFinite();
}

// The fine fit's series: per ENU channel of n0, y = C0^ V_b0 - V_n0 against [C0^ V_b0 x] psi (columns
// 0..2), for Up a velocity slope (column 3) and, where the body turns (an indexer), the accelerometer's
// bias in the body frame (columns 4..6: C0^ int C dt, which the turns tell from a tilt).
// The gyros' angle random walk tilts the tracked body at random: g times that tilt is a random walk of
// the horizontal velocity's rate (tilt_walk = g N), which the fit carries as its rate random walk.
std::vector<AngleSeries> fineSeries(const VelocityPoints& p, const Eigen::Matrix3d& c0, double white, double walk,
                                    double tilt_walk, bool accel_bias) {
  std::vector<AngleSeries> series(3);
  for (int c = 0; c < 3; ++c) {
    series[c].columns = {0, 1, 2};
    if (c == 2) series[c].columns.push_back(3);
    if (accel_bias) series[c].columns.insert(series[c].columns.end(), {4, 5, 6});
    series[c].regressors.assign(series[c].columns.size(), {});
    series[c].white_noise = white;
    series[c].angle_random_walk = walk;
    series[c].rate_random_walk = c < 2 ? tilt_walk : 0.0;
  }
  double x[7];
  for (std::size_t i = 0; i < p.time.size(); ++i) {
    const Eigen::Vector3d turned = c0 * p.body[i];
    const Eigen::Vector3d y = turned - p.reference[i];
    const Eigen::Matrix3d s = skew(turned), bias = c0 * p.by_accel_bias[i];
    for (int c = 0; c < 3; ++c) {
      std::size_t k = 0;
      for (int j = 0; j < 3; ++j) x[k++] = s(c, j);
      if (c == 2) x[k++] = p.time[i];
      if (accel_bias) {
        for (int j = 0; j < 3; ++j) x[k++] = bias(c, j);
      }
      series[c].push(p.time[i], 0, y(c), x);
    }
  }
  return series;
}

// Whether the body turned enough over the track for the accelerometer's bias to show apart from a tilt.
bool bodyTurns(const BodyAttitudeTrack& track) {
  const Eigen::AngleAxisd turn(track.attitudeAt(track.end()));
  return std::abs(turn.angle()) > kTurnForAccelerometerBias;
}

// The horizontal residuals' Allan variance fitted with 3 Q^2 / tau^2 + N^2 / tau: the base's velocity
// noise Q (m/s) and the accelerometer's random walk of velocity N (m/s/sqrt(s)).
void identifyNoise(const IntegratedAngleFit& fit, const std::vector<double>& time, double* white, double* walk) {
  const AngleFitResult& r = fit.result();
  const double spacing = medianSpacing(time), length = time.back() - time.front();
  Eigen::Matrix2d n = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  for (int c = 0; c < 2; ++c) {
    const AngleSeries& s = fit.channels()[c];
    std::vector<double> residual(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
      double model = 0.0;
      for (std::size_t k = 0; k < s.columns.size(); ++k) model += s.regressors[k][i] * r.parameters(s.columns[k]);
      residual[i] = s.angle[i] - model;
    }
    for (const AllanPoint& a : allanDeviation(residual, spacing).curve) {
      if (a.tau > 0.2 * length || a.clusters < 8) continue;
      const double avar = a.deviation * a.deviation, w = static_cast<double>(a.clusters) / (avar * avar + 1e-300);
      const Eigen::Vector2d x(1.0 / (a.tau * a.tau), 1.0 / a.tau);
      n += w * x * x.transpose();
      rhs += w * x * avar;
    }
  }
  if (!(n(0, 0) > 0.0) || !(n(1, 1) > 0.0)) {  // too short for a curve: the fit's own measure, no walk
    *white = std::max(std::max(r.white_noise[0], r.white_noise[1]), 1e-9);
    *walk = 0.0;
    return;
  }
  Eigen::Vector2d q = n.ldlt().solve(rhs);
  if (!(q(0) >= 0.0)) q = Eigen::Vector2d(0.0, rhs(1) / n(1, 1));
  if (!(q(1) >= 0.0)) q = Eigen::Vector2d(rhs(0) / n(0, 0), 0.0);
  *white = std::max(std::sqrt(std::max(q(0), 0.0) / 3.0), 1e-9);
  *walk = std::sqrt(std::max(q(1), 0.0));
}

// The fit's response of psi to a per-point perturbation of V_b0 (3 x m per source, turned by C0^).
Eigen::Matrix3Xd responseOf(const IntegratedAngleFit& fit, const std::vector<Eigen::Matrix3d>& by,
                            const Eigen::Matrix3d& c0) {
  Eigen::Matrix3Xd j = Eigen::Matrix3Xd::Zero(3, 3);
  for (int source = 0; source < 3; ++source) {
    for (int c = 0; c < 3; ++c) {
      std::vector<double> values(by.size());
      for (std::size_t i = 0; i < by.size(); ++i) values[i] = (c0 * by[i].col(source))(c);
      j.col(source) += fit.response(c, values).head<3>();
    }
  }
  return j;
}

}  // namespace

Eigen::Vector3d turningGravityIntegral(const Eigen::Vector3d& u, const Eigen::Vector3d& v, double t) {
  const double a = kEarthRotationRate * t;
  const Eigen::Vector3d along = u * u.dot(v), across = v - along, side = u.cross(v);
  const double half = std::sin(0.5 * a);
  return along * t + across * (t * sinc(a)) + side * (2.0 * half * half / kEarthRotationRate);
}

InertialFrameResult alignInInertialFrame(const BodyAttitudeTrack& track, const InertialFrameInput& in) {
  InertialFrameResult out;
  out.seconds = track.end() - track.start();
  const VelocityPoints p = integrateVelocities(track, in);
  out.records = p.records;
  if (p.records < 100 || p.time.size() < 20 || p.time.back() < 10.0) {
    out.problem = "too few accelerometer records within the gyros' track (at least 100 over 10 s)";
    return out;
  }
  out.gravity = (p.force_sum / static_cast<double>(p.records)).norm();
  Eigen::Matrix3d c0;
  if (!coarseAlignment(p, &c0)) {
    out.problem = "gravity's turn with the Earth is not seen in the window";
    return out;
  }
  out.coarse_start_to_enu = c0;
  double white = -1.0, walk = 0.0;
  const bool accel_bias = bodyTurns(track);
  for (int step = 0; step <= kGaussNewtonSteps; ++step) {
    IntegratedAngleFit fit(accel_bias ? 7 : 4,
                           fineSeries(p, c0, white, walk, out.gravity * in.gyro_angle_random_walk, accel_bias));
    const AngleFitResult& r = fit.solve(1e12);
    if (!r.ok) {
      out.problem = "the zero-velocity fit: " + r.problem;
      return out;
    }
    const Eigen::Matrix3d about = c0;  // the linearisation point of this solve
    c0 = rotationVectorToQuaternion(r.parameters.head<3>()).toRotationMatrix() * c0;
    if (step + 1 == kGaussNewtonSteps) identifyNoise(fit, p.time, &white, &walk);
    if (step < kGaussNewtonSteps) continue;
    // The last solve, about the converged C0 with the measured noise: its covariance and responses.
    const double length = p.time.back();
    const Eigen::Vector3d u(0.0, std::cos(in.latitude), std::sin(in.latitude));
    const Eigen::Matrix3d to_end = Eigen::AngleAxisd(-kEarthRotationRate * out.seconds, u).toRotationMatrix();
    // Each share symmetric to the last bit (a covariance turned by a rotation is, but for rounding).
    auto symmetric = [](const Eigen::Matrix3d& m) { return Eigen::Matrix3d(0.5 * (m + m.transpose())); };
    auto share = [&](const Eigen::Matrix3Xd& j, double sigma) {
      return symmetric(to_end * (sigma * sigma * j * j.transpose()) * to_end.transpose());
    };
    const Eigen::Matrix3Xd by_gyro = responseOf(fit, p.by_gyro_bias, about);
    InertialFrameBudget& b = out.budget;
    b.noise = symmetric(to_end * r.covariance().topLeftCorner<3, 3>() * to_end.transpose());
    b.residual_bias = share(by_gyro, in.gyro_bias);
    b.drift_harmonics = share(by_gyro, in.gyro_drift_harmonics);
    b.bias_random_walk =
        share(by_gyro, std::sqrt(in.gyro_rate_random_walk * in.gyro_rate_random_walk * length / 3.0 +
                                 1.2 * in.gyro_angle_random_walk * in.gyro_angle_random_walk / length));
    // A fitted accelerometer bias leaves no share of its own: its estimate's noise is in the fit's.
    b.level = (accel_bias ? Eigen::Matrix3d(Eigen::Matrix3d::Zero())
                          : share(responseOf(fit, p.by_accel_bias, about), in.accel_bias)) +
              share(responseOf(fit, p.by_mounting, about), in.accel_mounting);
    // A body bias: the fit's estimate moves by J b, and the track's end turns by C0 S(T) b.
    out.bias_to_attitude = -to_end * (by_gyro + c0 * track.biasResponseAt(track.end()));
    out.start_to_enu = c0;
    out.end_to_enu = to_end * c0 * track.attitudeAt(track.end());
    out.velocity_white = white;
    out.velocity_random_walk = walk;
    out.scatter = std::max(r.scatter[0], r.scatter[1]);
    out.up_start = c0.transpose().col(2);
  }
  out.ok = true;
  return out;
}

}  // namespace core
}  // namespace hrg_gyro
