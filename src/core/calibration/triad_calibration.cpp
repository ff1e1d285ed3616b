#include "hrg_gyro/core/calibration/triad_calibration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hrg_gyro/core/estimation/plateau_detector.h"
#include "hrg_gyro/core/model/model_pair_evaluator.h"

namespace hrg_gyro {
namespace core {
namespace {

const char* const kAxisLetters[3] = {"x", "y", "z"};
const char* const kStreamNames[kTriadStreamCount] = {"fixture", "table", "axis 0", "axis 1", "axis 2"};

// s of its own stamps a stream may stay on the old timeline after another went back for good.
constexpr double kFollowGiveUp = 60.0;

std::array<StampTimeline, kTriadStreamCount> makeTimelines(const StampRule& rule) {
  const StampTimeline t(rule);
  return {{t, t, t, t, t}};
}

/// The Earth's rate in the platter's frame (z up along the table axis, x at the table's zero mark
/// turned by the table angle): the zero mark points at `azimuth` from North towards East, and a
/// positive (counter-clockwise seen from above) table angle turns it towards West.
Eigen::Vector3d earthInPlatter(double latitude, double azimuth, double table_angle) {
  const double heading = azimuth - table_angle;
  const double horizontal = kEarthRotationRate * std::cos(latitude);
  return Eigen::Vector3d(horizontal * std::cos(heading), horizontal * std::sin(heading),
                         kEarthRotationRate * std::sin(latitude));
}

/// Interpolates a stored series at `stamp` (series sorted by stamp); false outside it or across a gap.
bool interpolate(const std::vector<std::pair<Nanoseconds, double>>& series, Nanoseconds stamp, double max_gap,
                 double* value) {
  const auto after =
      std::lower_bound(series.begin(), series.end(), stamp,
                       [](const std::pair<Nanoseconds, double>& s, Nanoseconds t) { return s.first < t; });
  if (after == series.end()) return false;
  if (after->first == stamp) {
    *value = after->second;
    return true;
  }
  if (after == series.begin()) return false;
  const auto before = after - 1;
  const double span = toSeconds(after->first - before->first);
  if (!(span > 0.0) || span > max_gap) return false;
  const double f = toSeconds(stamp - before->first) / span;
  *value = before->second + f * (after->second - before->second);
  return true;
}

/// Least squares of y on the columns of x for one axis and position: the response to the table
/// angle with its standard error (from the residuals, widened for their lag-one correlation).
struct ResponseFit {
  bool ok = false;
  double value = 0.0, std = 0.0;
};

ResponseFit fitResponse(const std::vector<Eigen::Vector4d>& x, const std::vector<double>& y) {
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
  double squares = 0.0, lag = 0.0, previous = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double e = y[k] - x[k].cwiseQuotient(scale).dot(beta);
    squares += e * e;
    if (k > 0) lag += e * previous;
    previous = e;
  }
  const double variance = squares / (n - 4);
  // Increments of window means share the window between them: white noise makes neighbours
  // anti-correlated (rho = -1/2), which the plain formula would overstate; anything positive widens.
  const double rho = std::clamp(lag / squares, -0.5, 0.9);
  const double inflation = std::max(0.0, 1.0 + 2.0 * rho);
  r.value = beta(0) / scale(0);
  r.std = std::sqrt(variance * inverse(0, 0) * std::max(inflation, 0.25)) / scale(0);
  r.ok = std::isfinite(r.value) && std::isfinite(r.std);
  return r;
}

}  // namespace

std::vector<std::string> TriadCalibrationSettings::keys() {
  return {"azimuth", "window", "store_rate", "vertical_tolerance", "min_rest", "min_position_time", "max_misalignment"};
}

TriadCalibrationSettings TriadCalibrationSettings::parse(const YamlField& f) {
  f.requireMap();
  f.rejectUnknownKeys(keys());
  TriadCalibrationSettings s;
  s.azimuth = f.getDouble("azimuth", s.azimuth);
  if (!(std::abs(s.azimuth) <= 2.0 * kPi)) f["azimuth"].fail("must be in [-2 pi, 2 pi] rad");
  auto positive = [&](const char* key, double* value) {
    *value = f.getDouble(key, *value);
    if (!(*value > 0.0)) f[key].fail("must be positive");
  };
  positive("window", &s.window);
  positive("store_rate", &s.store_rate);
  positive("vertical_tolerance", &s.vertical_tolerance);
  positive("min_rest", &s.min_rest);
  positive("min_position_time", &s.min_position_time);
  positive("max_misalignment", &s.max_misalignment);
  if (s.vertical_tolerance >= 0.5) f["vertical_tolerance"].fail("must be below 0.5");
  return s;
}

bool acceptFixtureOrientation(FixtureRecord* record) {
  const double norm = record->body_to_table.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) return false;
  record->body_to_table.normalize();
  return true;
}

TriadCalibration::TriadCalibration(const CalibrationSettings& axis_settings, const TriadCalibrationSettings& settings,
                                   const std::array<GyroParameters, 3>& priors, const TriadParameters& prior_triad)
    : axis_settings_(axis_settings),
      settings_(settings),
      priors_(priors),
      prior_triad_(prior_triad),
      timelines_(makeTimelines(axis_settings.stampRule())) {
  axis_settings_.method = CalibrationMethodKind::kDualRate;
  for (int i = 0; i < 3; ++i) sessions_[i] = std::make_unique<CalibrationSession>(axis_settings_, priors_[i]);
}

bool TriadCalibration::admit(int stream, Nanoseconds stamp) {
  Nanoseconds others = 0;  // the newest good stamp of the other streams
  for (int s = 0; s < kTriadStreamCount; ++s) {
    if (s != stream && timelines_[s].started()) others = std::max(others, timelines_[s].last());
  }
  TriadStreamRejects& r = rejects_[stream];
  switch (timelines_[stream].check(stamp, others)) {
    case StampVerdict::kNext:
    case StampVerdict::kResumedAhead:
      return true;
    case StampVerdict::kNewTimeline:
      restart();
      for (int s = 0; s < kTriadStreamCount; ++s) {
        if (s != stream) timelines_[s].expectJumpBack(kFollowGiveUp);
      }
      return true;
    case StampVerdict::kNonPositive:
      ++r.bad_stamp;
      return false;
    case StampVerdict::kDuplicate:
    case StampVerdict::kBehind:
      ++r.out_of_order;
      return false;
    case StampVerdict::kJumpedBack:
    case StampVerdict::kJumpedAhead:
      ++r.stamp_jump;
      return false;
  }
  return false;
}

void TriadCalibration::restart() {
  ++restarts_;
  for (int i = 0; i < 3; ++i) {
    sessions_[i] = std::make_unique<CalibrationSession>(axis_settings_, priors_[i]);
    waves_[i].clear();
    wave_blocks_[i] = BlockMean();
  }
  fixtures_.clear();
  table_.clear();
  table_rates_.clear();
  table_block_ = BlockMean();
  table_unwrapped_ = NAN;
  origin_ = 0;
}

void TriadCalibration::noteRejects(TriadOutcome* o) const {
  for (int s = 0; s < kTriadStreamCount; ++s) {
    const TriadStreamRejects& r = rejects_[s];
    if (r.total() == 0) continue;
    const std::string name = s >= kAxisStream0 ? "axis " + prior_triad_.axes[s - kAxisStream0] : kStreamNames[s];
    std::string what = std::to_string(r.total()) + " " + name + " records dropped (";
    if (r.bad_value > 0) {
      what += std::to_string(r.bad_value) + (s == kFixtureStream ? " orientation not a rotation, " : " non-finite, ");
    }
    what += std::to_string(r.bad_stamp) + " zero stamp, " + std::to_string(r.out_of_order) + " out of order, " +
            std::to_string(r.stamp_jump) + " stamp jump)";
    o->notes.push_back(what);
  }
  if (restarts_ > 0) {
    o->notes.push_back("a stream's stamps went back for good " + std::to_string(restarts_) +
                       " time(s) (a recording across a restarted driver): the calibration started over");
  }
}

const FixtureRecord* TriadCalibration::fixtureAt(Nanoseconds stamp) const {
  const auto after = std::upper_bound(fixtures_.begin(), fixtures_.end(), stamp,
                                      [](Nanoseconds t, const FixtureRecord& r) { return t < r.stamp; });
  if (after == fixtures_.begin()) return nullptr;
  return &*(after - 1);
}

int TriadCalibration::verticalSign(const FixtureRecord& fixture, int axis) const {
  const Eigen::Vector3d u = fixture.body_to_table.toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ();
  if (u(axis) >= 1.0 - settings_.vertical_tolerance) return 1;
  if (u(axis) <= -1.0 + settings_.vertical_tolerance) return -1;
  return 0;
}

void TriadCalibration::addFixture(FixtureRecord record) {
  if (!acceptFixtureOrientation(&record)) {
    ++rejects_[kFixtureStream].bad_value;
    return;
  }
  if (!admit(kFixtureStream, record.stamp)) return;
  // Only changes are kept: a bench repeats its position every second.
  if (!fixtures_.empty()) {
    const FixtureRecord& last = fixtures_.back();
    if (last.index == record.index && last.locked == record.locked && last.name == record.name &&
        last.body_to_table.coeffs() == record.body_to_table.coeffs()) {
      return;
    }
  }
  fixtures_.push_back(record);
}

void TriadCalibration::addTurntable(Nanoseconds stamp, double angle, double rate, std::uint64_t sequence) {
  // A record with a bad rate goes to the sessions, which count it, but moves no stamp.
  if (std::isfinite(rate) && !admit(kTableStream, stamp)) return;
  if (origin_ == 0 && stamp > 0) origin_ = stamp;
  const FixtureRecord* fixture = fixtureAt(stamp);
  if (fixture && fixture->locked) {
    // An axis pointing down the table axis turns by minus the table angle, and sees minus the Earth's
    // vertical rate, which its session adds with a plus: both folded into the angle handed to it.
    const double vertical = priors_[0].earth_rate.verticalRate();
    const double t = toSeconds(stamp - origin_);
    for (int i = 0; i < 3; ++i) {
      const int sign = verticalSign(*fixture, i);
      if (sign == 0) continue;
      sessions_[i]->addRotationRecord(stamp, sign * angle + (sign - 1) * vertical * t,
                                      sign * rate + (sign - 1) * vertical, sequence);
    }
  }
  if (!std::isfinite(angle) || !std::isfinite(rate) || stamp <= 0) return;
  // Stored unwrapped: a controller may log its angle modulo 2 pi.
  const double unwrapped =
      std::isfinite(table_unwrapped_) ? angle + kTwoPi * std::round((table_unwrapped_ - angle) / kTwoPi) : angle;
  if (table_block_.count > 0 && stamp <= table_block_.last) return;  // out of order: not data here
  table_unwrapped_ = unwrapped;
  addToBlock(&table_block_, stamp, unwrapped, rate, &table_, &table_rates_);
}

void TriadCalibration::addToBlock(BlockMean* block, Nanoseconds stamp, double value, double rate,
                                  std::vector<StoredSample>* out, std::vector<double>* rates) const {
  const double length = 1.0 / settings_.store_rate;
  const bool ends = block->count > 0 && (stamp <= block->last || toSeconds(stamp - block->start) >= length ||
                                         toSeconds(stamp - block->last) > 0.5 * length);
  if (ends) {
    const double n = block->count;
    out->push_back({block->start + static_cast<Nanoseconds>(std::llround(1e9 * block->time / n)), block->value / n});
    if (rates) rates->push_back(block->rate / n);
    *block = BlockMean();
  }
  if (block->count == 0) block->start = stamp;
  block->last = stamp;
  block->time += toSeconds(stamp - block->start);
  block->value += value;
  block->rate += rate;
  ++block->count;
}

void TriadCalibration::addWave(int axis, Nanoseconds stamp, double theta, double frequency) {
  if (axis < 0 || axis > 2) throw std::invalid_argument("triad calibration: axis must be 0, 1 or 2");
  if (!std::isfinite(theta)) {
    ++rejects_[kAxisStream0 + axis].bad_value;
    return;
  }
  if (!admit(kAxisStream0 + axis, stamp)) return;
  if (origin_ == 0) origin_ = stamp;
  const FixtureRecord* fixture = fixtureAt(stamp);
  if (fixture && fixture->locked && verticalSign(*fixture, axis) != 0) {
    sessions_[axis]->addWave(stamp, theta, frequency);
  }
  if (!std::isfinite(theta) || stamp <= 0) return;
  if (wave_blocks_[axis].count > 0 && stamp <= wave_blocks_[axis].last) return;  // out of order
  addToBlock(&wave_blocks_[axis], stamp, theta, 0.0, &waves_[axis], nullptr);
}

std::vector<TriadCalibration::Interval> TriadCalibration::lockedIntervals() const {
  std::vector<Interval> out;
  for (std::size_t k = 0; k < fixtures_.size(); ++k) {
    if (!fixtures_[k].locked) continue;
    Interval interval;
    interval.fixture = fixtures_[k];
    interval.from = fixtures_[k].stamp;
    interval.to = k + 1 < fixtures_.size() ? fixtures_[k + 1].stamp : std::numeric_limits<Nanoseconds>::max();
    out.push_back(interval);
  }
  return out;
}

TriadOutcome TriadCalibration::finish() const {
  TriadOutcome o;
  o.axis_names = prior_triad_.axes;
  o.triad = prior_triad_;
  noteRejects(&o);
  std::array<GyroParameters, 3> params = priors_;

  // A refusal for want of positions names the fixture records that never counted.
  const auto fixtureDrops = [this]() -> std::string {
    const TriadStreamRejects& r = rejects_[kFixtureStream];
    if (r.total() == 0) return "";
    return " (" + std::to_string(r.total()) + " fixture records were dropped: " + std::to_string(r.bad_value) +
           " orientation not a rotation, " + std::to_string(r.stamp_jump + r.out_of_order + r.bad_stamp) +
           " bad stamp)";
  };
  // Stage 1: each axis's K(theta) and D(theta).
  for (int i = 0; i < 3; ++i) {
    o.axes[i] = sessions_[i]->finish();
    bool vertical_somewhere = false;
    for (const FixtureRecord& f : fixtures_)
      vertical_somewhere = vertical_somewhere || (f.locked && verticalSign(f, i) != 0);
    const std::string axis = o.axis_names[i];
    if (!vertical_somewhere) {
      o.gate("axis_" + axis, false, 0.0, 1.0,
             "no locked position put axis " + axis + " along the table axis: add a position +" +
                 std::string(kAxisLetters[i]) + " or -" + kAxisLetters[i] + " (axis " + axis +
                 " up or down) with dual-rate plateaus" + fixtureDrops());
      continue;
    }
    o.gate("axis_" + axis, o.axes[i].accepted, o.axes[i].accepted ? 1.0 : 0.0, 1.0,
           o.axes[i].accepted ? "K(theta) and D(theta) of axis " + axis + " from its dual-rate plateaus"
                              : "axis " + axis + ": " + o.axes[i].reason);
    if (o.axes[i].accepted) params[i] = o.axes[i].parameters;
  }

  // Stage 2: each axis's compensated angle alpha(t) on the stored samples, with its new K and D.
  std::array<std::vector<std::pair<Nanoseconds, double>>, 3> alpha;
  for (int i = 0; i < 3; ++i) {
    ModelPairEvaluator models(params[i].scale_factor, params[i].drift);
    double a = 0.0;
    const std::vector<StoredSample>& w = waves_[i];
    for (std::size_t k = 0; k < w.size(); ++k) {
      if (k > 0) {
        const double dt = toSeconds(w[k].stamp - w[k - 1].stamp);
        double kk, dd;
        models.evaluate(0.5 * (w[k].value + w[k - 1].value), NAN, &kk, &dd);
        a += (w[k].value - w[k - 1].value - dd * dt) / kk;
      }
      alpha[i].push_back({w[k].stamp, a});
    }
  }
  std::array<std::vector<std::pair<Nanoseconds, double>>, 3> theta;
  for (int i = 0; i < 3; ++i)
    for (const StoredSample& w : waves_[i]) theta[i].push_back({w.stamp, w.value});
  std::vector<std::pair<Nanoseconds, double>> table;
  for (const StoredSample& s : table_) table.push_back({s.stamp, s.value});
  const double max_gap = std::max(axis_settings_.plateau.max_gap, 3.0 / settings_.store_rate);
  const double latitude = priors_[0].earth_rate.enabled ? priors_[0].earth_rate.latitude : 0.0;

  std::vector<Eigen::Vector3d> directions;  // u_p per fitted position
  std::vector<Eigen::Vector3d> responses, response_stds;
  for (const Interval& interval : lockedIntervals()) {
    // The table's plateaus within the position, judged as the sessions judge them.
    PlateauDetector detector(axis_settings_.plateau);
    std::vector<PlateauRecord> judged, out;
    for (std::size_t k = 0; k < table_.size(); ++k) {
      if (table_[k].stamp < interval.from || table_[k].stamp >= interval.to) continue;
      out.clear();
      detector.add(table_[k].stamp, table_[k].value, table_rates_[k], &out);
      judged.insert(judged.end(), out.begin(), out.end());
    }
    if (judged.size() < 3) continue;
    const Eigen::Matrix3d r_bt = interval.fixture.body_to_table.toRotationMatrix();
    const Eigen::Vector3d u = r_bt.transpose() * Eigen::Vector3d::UnitZ();
    // Samples of the position: on which plateau (id, settled, static), the table angle.
    struct Point {
      Nanoseconds stamp;
      double alpha[3];
      double theta[3];
      double phi;
      std::uint64_t plateau;
      bool is_static;
    };
    std::vector<Point> points;
    const std::vector<std::pair<Nanoseconds, double>>& base = alpha[0];
    for (const auto& s : base) {
      if (s.first < judged.front().stamp || s.first > judged.back().stamp) continue;
      const auto after = std::lower_bound(judged.begin(), judged.end(), s.first,
                                          [](const PlateauRecord& r, Nanoseconds t) { return r.stamp < t; });
      if (after == judged.end() || after == judged.begin()) continue;
      const PlateauRecord& b = *after;
      const PlateauRecord& a = *(after - 1);
      if (a.plateau.id != b.plateau.id || !a.plateau.settled) continue;
      Point p;
      p.stamp = s.first;
      p.plateau = b.plateau.id;
      p.is_static = b.plateau.is_static;
      bool ok = interpolate(table, s.first, max_gap, &p.phi);
      for (int i = 0; i < 3 && ok; ++i) {
        ok = interpolate(alpha[i], s.first, max_gap, &p.alpha[i]) &&
             interpolate(theta[i], s.first, max_gap, &p.theta[i]);
      }
      if (ok) points.push_back(p);
    }

    // Responses to the table's rate on the moving plateaus: window means, their increments.
    TriadPositionResponse response;
    response.position = interval.fixture.index;
    response.name = interval.fixture.name;
    response.table_axis = u;
    std::array<std::vector<Eigen::Vector4d>, 3> x;
    std::array<std::vector<double>, 3> y;
    double moving_time = 0.0;
    std::size_t begin = 0;
    while (begin < points.size()) {
      std::size_t end = begin;
      while (end < points.size() && points[end].plateau == points[begin].plateau) ++end;
      if (!points[begin].is_static && end - begin >= 4) {
        moving_time += toSeconds(points[end - 1].stamp - points[begin].stamp);
        // Window means along the plateau of alpha, phi, t and the Earth terms' integrals.
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
          const long index = static_cast<long>(std::floor(t / settings_.window));
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
        for (std::size_t m = 1; m < means.size(); ++m) {
          const Mean& a = means[m - 1];
          const Mean& b = means[m];
          const Eigen::Vector4d row(b.phi / b.n - a.phi / a.n, b.t / b.n - a.t / a.n, b.c / b.n - a.c / a.n,
                                    b.s / b.n - a.s / a.n);
          for (int i = 0; i < 3; ++i) {
            x[i].push_back(row);
            y[i].push_back(b.alpha[i] / b.n - a.alpha[i] / a.n);
          }
        }
      }
      begin = end;
    }
    response.duration = moving_time;
    response.increments = y[0].size();
    bool fitted = moving_time >= settings_.min_position_time;
    for (int i = 0; i < 3 && fitted; ++i) {
      const ResponseFit f = fitResponse(x[i], y[i]);
      fitted = f.ok;
      response.response(i) = f.value;
      response.response_std(i) = f.std;
    }
    if (fitted) {
      o.positions.push_back(response);
      directions.push_back(u);
      responses.push_back(response.response);
      response_stds.push_back(response.response_std);
    } else if (moving_time > 0.0) {
      o.notes.push_back("position " + response.name + ": " + std::to_string(moving_time) +
                        " s of moving plateaus, too little for the axes' responses (triad/min_position_time " +
                        std::to_string(settings_.min_position_time) + " s)");
    }

    // Rests: the axes' mean rates against the Earth's.
    begin = 0;
    while (begin < points.size()) {
      std::size_t end = begin;
      while (end < points.size() && points[end].plateau == points[begin].plateau) ++end;
      const double duration = end > begin ? toSeconds(points[end - 1].stamp - points[begin].stamp) : 0.0;
      if (points[begin].is_static && duration >= settings_.min_rest) {
        TriadRest rest;
        rest.position = interval.fixture.index;
        rest.name = interval.fixture.name;
        rest.duration = duration;
        double phi = 0.0;
        for (std::size_t k = begin; k < end; ++k) phi += points[k].phi / (end - begin);
        rest.table_angle = phi;
        for (int i = 0; i < 3; ++i) {
          // The slope of alpha over the rest, and its standard error from the residuals.
          double st = 0, sa = 0, stt = 0, sta = 0;
          const double n = static_cast<double>(end - begin);
          for (std::size_t k = begin; k < end; ++k) {
            const double t = toSeconds(points[k].stamp - points[begin].stamp);
            st += t;
            sa += points[k].alpha[i];
            stt += t * t;
            sta += t * points[k].alpha[i];
          }
          const double var_t = stt - st * st / n;
          const double slope = (sta - st * sa / n) / var_t;
          double squares = 0.0;
          for (std::size_t k = begin; k < end; ++k) {
            const double t = toSeconds(points[k].stamp - points[begin].stamp);
            const double e = points[k].alpha[i] - (sa / n + slope * (t - st / n));
            squares += e * e;
          }
          rest.axis_rates(i) = slope;
          rest.axis_rates_std(i) = std::sqrt(squares / (n - 2.0) / var_t);
          // Stage 1's D(theta) is uncertain where the wave rests: that error enters the rate as
          // -dD / K, the same in every rest at this angle (not averaged away by more rests).
          double theta_mean = 0.0;
          for (std::size_t k = begin; k < end; ++k) theta_mean += points[k].theta[i] / n;
          if (!o.axes[i].drift.empty() && !o.axes[i].scale_factor.empty()) {
            const HarmonicFitResult& d = o.axes[i].drift.front();
            double variance = d.mean_std * d.mean_std;
            for (std::size_t h = 0; h < d.orders.size(); ++h) {
              variance += std::pow(d.cos_std[h] * std::cos(d.orders[h] * theta_mean), 2) +
                          std::pow(d.sin_std[h] * std::sin(d.orders[h] * theta_mean), 2);
            }
            rest.axis_drift_std(i) = std::sqrt(variance) / std::abs(o.axes[i].scale_factor.front().mean);
          }
        }
        rest.earth_body = r_bt.transpose() * earthInPlatter(latitude, settings_.azimuth, phi);
        o.rests.push_back(rest);
      }
      begin = end;
    }
  }

  // A from the responses: per axis, least squares over the positions' table-axis directions.
  Eigen::MatrixXd u(directions.size(), 3);
  for (std::size_t p = 0; p < directions.size(); ++p) u.row(p) = directions[p].transpose();
  o.positions_fitted = directions.size();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(u.rows() > 0 ? u : Eigen::MatrixXd::Zero(1, 3));
  const double weakest = directions.empty() ? 0.0 : svd.singularValues().minCoeff();
  if (directions.size() < 3 || weakest < 0.3) {
    std::string missing;
    for (int j = 0; j < 3; ++j) {
      double best = 0.0;
      for (const Eigen::Vector3d& d : directions) best = std::max(best, std::abs(d(j)));
      if (best < 0.5)
        missing += (missing.empty() ? "" : ", ") + std::string("+") + kAxisLetters[j] + " or -" + kAxisLetters[j];
    }
    o.gate("positions", false, weakest, 0.3,
           std::to_string(directions.size()) +
               " fixture positions with the table turning: their table axes do not "
               "span the body frame" +
               (missing.empty() ? std::string() : "; missing: a position " + missing) +
               " (body axis along the table axis)" + fixtureDrops());
    o.decide();
    return o;
  }
  Eigen::Matrix3d a_std = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (std::size_t p = 0; p < directions.size(); ++p) {
      const double w = 1.0 / std::max(response_stds[p](i) * response_stds[p](i), 1e-30);
      normal.noalias() += w * directions[p] * directions[p].transpose();
      rhs.noalias() += w * directions[p] * responses[p](i);
    }
    const Eigen::Matrix3d inverse = normal.inverse();
    const Eigen::Vector3d row = inverse * rhs;
    double chi = 0.0;
    for (std::size_t p = 0; p < directions.size(); ++p) {
      chi += std::pow((responses[p](i) - row.dot(directions[p])) / std::max(response_stds[p](i), 1e-15), 2);
    }
    o.fit_chi_square(i) = chi;
    // Where the positions disagree beyond their own errors (a fixture off by more than its
    // plan), the scatter widens the standard errors.
    const double dof = static_cast<double>(directions.size()) - 3.0;
    const double widen = dof > 0.0 ? std::max(1.0, chi / dof) : 1.0;
    o.body_to_axis.row(i) = row.transpose();
    for (int j = 0; j < 3; ++j) a_std(i, j) = std::sqrt(inverse(j, j) * widen);
  }
  o.body_to_axis_std = a_std;
  const Eigen::Matrix3d m = o.body_to_axis.inverse();
  // dM = -M dA M: each entry's variance from the A entries' taken as independent.
  Eigen::Matrix3d m_std = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double v = 0.0;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) v += std::pow(m(i, k) * m(l, j) * a_std(k, l), 2);
      m_std(i, j) = std::sqrt(v);
    }
  const double largest = (o.body_to_axis - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  o.gate("misalignment", largest <= settings_.max_misalignment, largest, settings_.max_misalignment,
         "largest |A - I| " + formatShort(largest, 3) + " (axes' misalignment angles and residual scales)");
  o.triad.axis_to_body = m;
  o.triad.axis_to_body_std = m_std;

  // Stage 3: the body bias from the rests.
  if (!o.rests.empty()) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), noise = Eigen::Vector3d::Zero();
    for (TriadRest& r : o.rests) {
      r.bias = m * r.axis_rates - r.earth_body;
      sum += r.bias;
      noise += (m * r.axis_rates_std.asDiagonal()).rowwise().norm().cwiseAbs2();
    }
    const double n = static_cast<double>(o.rests.size());
    const Eigen::Vector3d mean = sum / n;
    Eigen::Vector3d scatter = Eigen::Vector3d::Zero();
    Eigen::Vector3d drift_variance = Eigen::Vector3d::Zero();  // per axis, mean over the rests
    for (const TriadRest& r : o.rests) {
      scatter += (r.bias - mean).cwiseAbs2();
      drift_variance += r.axis_drift_std.cwiseAbs2() / n;
    }
    Eigen::Vector3d std = (noise / (n * n)).cwiseSqrt();
    if (n >= 3.0) std = std.cwiseMax((scatter / ((n - 1.0) * n)).cwiseSqrt());
    // Plus the axes' D(theta) uncertainty at the rests, through M: common to the rests, so it is
    // added, not divided by their number.
    const Eigen::Vector3d drift_part = (m.cwiseAbs2() * drift_variance).cwiseSqrt();
    std = (std.cwiseAbs2() + drift_part.cwiseAbs2()).cwiseSqrt();
    o.triad.bias = mean;
    o.triad.bias_std = std;
    o.bias_estimated = true;
  } else {
    o.notes.push_back("no rest of " + formatShort(settings_.min_rest, 3) +
                      " s or more in a locked position: the body bias was not estimated (the prior's kept)");
  }
  o.triad.calibration.method = ParameterOrigin::calibratedBy(CalibrationMethodKind::kTriad);
  o.triad.calibration.time = utcNow();
  for (int i = 0; i < 3; ++i) {
    if (o.axes[i].accepted)
      o.axes[i].parameters.calibration.method = ParameterOrigin::calibratedBy(CalibrationMethodKind::kTriad);
  }
  o.decide();
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
