#include "hrg_gyro/core/calibration/triad/triad_axis_directions.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/number_format.h"

namespace hrg_gyro {
namespace core {
namespace {

/// The increments of one position's window means: per axis the regressors (phi, t, C, S) and alpha.
struct WindowIncrements {
  std::array<std::vector<Eigen::Vector4d>, 3> x;
  std::array<std::vector<double>, 3> y;
  std::vector<std::size_t> chain_starts;  ///< index of each plateau's first increment
  double moving_time = 0.0;               ///< s of moving plateau data
};

/// Window means along one moving plateau (samples [begin, end)) of alpha, phi, t and the Earth terms'
/// integrals; their increments appended to *w.
void addPlateauIncrements(const std::vector<TriadPositionSample>& points, std::size_t begin, std::size_t end,
                          double window, WindowIncrements* w) {
  struct Mean {
    double alpha[3] = {0, 0, 0}, phi = 0, t = 0, c = 0, s = 0, n = 0;
  };
  std::vector<Mean> means;
  Mean sum;
  double c_int = 0.0, s_int = 0.0;
  const Nanoseconds t0 = points[begin].stamp;
  long window_index = 0;
  for (std::size_t k = begin; k < end; ++k) {
    const double t = toSeconds(points[k].stamp - t0);
    if (k > begin) {
      const double dt = toSeconds(points[k].stamp - points[k - 1].stamp);
      c_int += 0.5 * (std::cos(points[k].phi) + std::cos(points[k - 1].phi)) * dt;
      s_int += 0.5 * (std::sin(points[k].phi) + std::sin(points[k - 1].phi)) * dt;
    }
    const long index = static_cast<long>(std::floor(t / window));
    if (index != window_index && sum.n > 0) {
      means.push_back(sum);
      sum = Mean();
    }
    window_index = index;
    for (int i = 0; i < 3; ++i) sum.alpha[i] += points[k].alpha[i];
    sum.phi += points[k].phi;
    sum.t += t;
    sum.c += c_int;
    sum.s += s_int;
    sum.n += 1.0;
  }
  w->chain_starts.push_back(w->y[0].size());
  for (std::size_t m = 1; m < means.size(); ++m) {
    const Mean& a = means[m - 1];
    const Mean& b = means[m];
    const Eigen::Vector4d row(b.phi / b.n - a.phi / a.n, b.t / b.n - a.t / a.n, b.c / b.n - a.c / a.n,
                              b.s / b.n - a.s / a.n);
    for (int i = 0; i < 3; ++i) {
      w->x[i].push_back(row);
      w->y[i].push_back(b.alpha[i] / b.n - a.alpha[i] / a.n);
    }
  }
}

/// Least squares of y on the columns of x for one axis and position: the response to the table
/// angle with its standard error. The increments' errors are the window means' own noise (each
/// increment has two window means; neighbours share one, with opposite signs) plus noise white from
/// increment to increment (angle random walk, table errors): Cov = a D D^T + b I, a and b read from
/// the residuals' lag-one and lag-zero covariances within the plateaus, and the standard error is
/// the sandwich (X^T X)^-1 X^T Cov X (X^T X)^-1. Treating the increments as independent instead
/// would count the window means' noise once per increment, where along a plateau it telescopes.
struct ResponseFit {
  bool ok = false;
  double value = 0.0, std = 0.0;
};

ResponseFit fitResponse(const std::vector<Eigen::Vector4d>& x, const std::vector<double>& y,
                        const std::vector<std::size_t>& chain_starts) {
  ResponseFit r;
  const std::size_t n = y.size();
  if (n < 12) return r;
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  Eigen::Vector4d scale = Eigen::Vector4d::Zero();
  for (std::size_t k = 0; k < n; ++k) scale += x[k].cwiseAbs2();
  scale = scale.cwiseSqrt();
  for (int j = 0; j < 4; ++j) {
    if (!(scale(j) > 0.0)) return r;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector4d xs = x[k].cwiseQuotient(scale);
    normal.noalias() += xs * xs.transpose();
    rhs.noalias() += xs * y[k];
  }
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(normal);
  if (!lu.isInvertible()) return r;
  const Eigen::Matrix4d inverse = lu.inverse();
  const Eigen::Vector4d beta = inverse * rhs;
  // Neighbours: consecutive increments of one plateau.
  std::vector<bool> follows(n, true);
  for (std::size_t start : chain_starts)
    if (start < n) follows[start] = false;
  follows[0] = false;
  double squares = 0.0, lag = 0.0, previous = 0.0;
  std::size_t pairs = 0;
  Eigen::Matrix4d products = Eigen::Matrix4d::Zero(), neighbours = Eigen::Matrix4d::Zero();
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector4d xs = x[k].cwiseQuotient(scale);
    const double e = y[k] - xs.dot(beta);
    squares += e * e;
    products.noalias() += xs * xs.transpose();
    if (follows[k]) {
      lag += e * previous;
      ++pairs;
      const Eigen::Vector4d before = x[k - 1].cwiseQuotient(scale);
      neighbours.noalias() += xs * before.transpose() + before * xs.transpose();
    }
    previous = e;
  }
  const double variance = squares / (n - 4), covariance = pairs > 0 ? lag / pairs : 0.0;
  // lag zero: 2a + b, lag one: -a. A positive lag one (a wander) is charged to b, widened by it.
  const double a = std::max(0.0, -covariance);
  const double b = std::max(0.0, variance - 2.0 * a) * (covariance > 0.0 ? 1.0 + 2.0 * covariance / variance : 1.0);
  const Eigen::Matrix4d meat = a * (2.0 * products - neighbours) + b * products;
  const double beta_variance = (inverse * meat * inverse)(0, 0);
  r.value = beta(0) / scale(0);
  r.std = std::sqrt(std::max(0.0, beta_variance)) / scale(0);
  r.ok = std::isfinite(r.value) && std::isfinite(r.std);
  return r;
}

/// Whether the positions' table axes span the body frame; the gate "positions" failed if not.
bool spanTheBodyFrame(const std::vector<TriadPositionResponse>& positions, const std::string& refusal_note,
                      TriadOutcome* o) {
  Eigen::MatrixXd u(positions.size(), 3);
  for (std::size_t p = 0; p < positions.size(); ++p) u.row(p) = positions[p].table_axis.transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(u.rows() > 0 ? u : Eigen::MatrixXd::Zero(1, 3));
  const double weakest = positions.empty() ? 0.0 : svd.singularValues().minCoeff();
  if (positions.size() >= 3 && weakest >= 0.3) return true;
  std::string missing;
  for (int j = 0; j < 3; ++j) {
    double best = 0.0;
    for (const TriadPositionResponse& p : positions) best = std::max(best, std::abs(p.table_axis(j)));
    if (best < 0.5) missing += (missing.empty() ? "" : ", ") + alongTableAxis(j);
  }
  o->gate("positions", false, weakest, 0.3,
          std::to_string(positions.size()) +
              " fixture positions with the table turning: their table axes do not "
              "span the body frame" +
              (missing.empty() ? std::string() : "; missing: a position " + missing) +
              " (body axis along the table axis)" + refusal_note);
  return false;
}

}  // namespace

std::string alongTableAxis(int body_axis) {
  const char* const letters[3] = {"x", "y", "z"};
  return std::string("+") + letters[body_axis] + " or -" + letters[body_axis];
}

void measureResponses(const TriadLockedPosition& position, const TriadCalibrationSettings& settings, TriadOutcome* o) {
  TriadPositionResponse response;
  response.position = position.index;
  response.name = position.name;
  response.table_axis = position.table_axis;
  WindowIncrements w;
  for (const auto& [begin, end] : plateauRuns(position.samples)) {
    if (position.samples[begin].is_static || end - begin < 4) continue;
    w.moving_time += toSeconds(position.samples[end - 1].stamp - position.samples[begin].stamp);
    addPlateauIncrements(position.samples, begin, end, settings.window, &w);
  }
  response.duration = w.moving_time;
  response.increments = w.y[0].size();
  bool fitted = w.moving_time >= settings.min_position_time;
  for (int i = 0; i < 3 && fitted; ++i) {
    const ResponseFit f = fitResponse(w.x[i], w.y[i], w.chain_starts);
    fitted = f.ok;
    response.response(i) = f.value;
    response.response_std(i) = f.std;
  }
  if (fitted) {
    o->positions.push_back(response);
  } else if (w.moving_time > 0.0) {
    o->notes.push_back("position " + response.name + ": " + std::to_string(w.moving_time) +
                       " s of moving plateaus, too little for the axes' responses (triad/min_position_time " +
                       std::to_string(settings.min_position_time) + " s)");
  }
}

bool fitAxisDirections(const TriadCalibrationSettings& settings, const std::string& refusal_note, TriadOutcome* o) {
  const std::vector<TriadPositionResponse>& positions = o->positions;
  o->positions_fitted = positions.size();
  if (!spanTheBodyFrame(positions, refusal_note, o)) return false;
  Eigen::Matrix3d a_std = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (const TriadPositionResponse& p : positions) {
      const double w = 1.0 / std::max(p.response_std(i) * p.response_std(i), 1e-30);
      normal.noalias() += w * p.table_axis * p.table_axis.transpose();
      rhs.noalias() += w * p.table_axis * p.response(i);
    }
    const Eigen::Matrix3d inverse = normal.inverse();
    const Eigen::Vector3d row = inverse * rhs;
    double chi = 0.0;
    for (const TriadPositionResponse& p : positions) {
      chi += std::pow((p.response(i) - row.dot(p.table_axis)) / std::max(p.response_std(i), 1e-15), 2);
    }
    o->fit_chi_square(i) = chi;
    // Where the positions disagree beyond their own errors (a fixture off by more than its
    // plan), the scatter widens the standard errors.
    const double dof = static_cast<double>(positions.size()) - 3.0;
    const double widen = dof > 0.0 ? std::max(1.0, chi / dof) : 1.0;
    o->body_to_axis.row(i) = row.transpose();
    for (int j = 0; j < 3; ++j) a_std(i, j) = std::sqrt(inverse(j, j) * widen);
  }
  o->body_to_axis_std = a_std;
  const Eigen::Matrix3d m = o->body_to_axis.inverse();
  const double largest = largestMisalignment(o->body_to_axis);
  o->gate("misalignment", largest <= settings.max_misalignment, largest, settings.max_misalignment,
          "largest |A - I| " + formatShort(largest, 3) + " (axes' misalignment angles and residual scales)");
  o->triad.axis_to_body = m;
  o->triad.axis_to_body_std = axisToBodyStd(m, a_std);
  return true;
}

}  // namespace core
}  // namespace hrg_gyro
