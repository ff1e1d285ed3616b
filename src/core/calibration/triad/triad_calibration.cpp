#include "hrg_gyro/core/calibration/triad/triad_calibration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "hrg_gyro/core/calibration/triad/triad_axis_directions.h"
#include "hrg_gyro/core/calibration/triad/triad_body_bias.h"
#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace core {
namespace {

const char* const kStreamNames[kTriadStreamCount] = {"fixture", "table", "axis 0", "axis 1", "axis 2"};

// s of its own stamps a stream may stay on the old timeline after another went back for good.
constexpr double kFollowGiveUp = 60.0;

std::array<StampTimeline, kTriadStreamCount> makeTimelines(const StampRule& rule) {
  const StampTimeline t(rule);
  return {{t, t, t, t, t}};
}

}  // namespace

bool TriadStreamRejects::admits(StampVerdict verdict) {
  switch (verdict) {
    case StampVerdict::kNext:
    case StampVerdict::kResumedAhead:
    case StampVerdict::kNewTimeline:
      return true;
    case StampVerdict::kNonPositive:
      ++bad_stamp;
      return false;
    case StampVerdict::kDuplicate:
    case StampVerdict::kBehind:
      ++out_of_order;
      return false;
    case StampVerdict::kJumpedBack:
    case StampVerdict::kJumpedAhead:
      ++stamp_jump;
      return false;
  }
  return false;
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
  for (int i = 0; i < 3; ++i) sessions_[i] = makeSession(i);
}

std::unique_ptr<CalibrationSession> TriadCalibration::makeSession(int axis) {
  auto session = std::make_unique<CalibrationSession>(axis_settings_, priors_[axis]);
  session->modelHorizontalEarthRate(kHorizontalSlots,
                                    [this, axis](PlateauSample* sample) { tagHorizontal(axis, sample); });
  return session;
}

void TriadCalibration::tagHorizontal(int axis, PlateauSample* sample) {
  const FixtureRecord* fixture = fixtureAt(sample->stamp);
  if (!fixture || !fixture->locked) return;
  const int sign = verticalSign(*fixture, axis);
  if (sign == 0) return;
  // One slot per clamping: a position clamped again leans anew.
  std::vector<std::size_t>& slots = slot_records_[axis];
  const std::size_t record = static_cast<std::size_t>(fixture - fixtures_.data());
  const auto known = std::find(slots.begin(), slots.end(), record);
  if (known == slots.end() && slots.size() >= static_cast<std::size_t>(kHorizontalSlots)) {
    ++unslotted_[axis];
    return;
  }
  if (known == slots.end()) slots.push_back(record);
  // The table angle back from the angle addTurntable handed the session.
  const double vertical = priors_[0].earth_rate.verticalRate();
  const double table_angle =
      (sample->rotation_angle - (sign - 1) * vertical * toSeconds(sample->stamp - origin_)) / sign;
  sample->horizontal_slot = static_cast<int>(std::find(slots.begin(), slots.end(), record) - slots.begin());
  sample->horizontal_phase = settings_.azimuth - table_angle;
}

bool TriadCalibration::admit(int stream, Nanoseconds stamp) {
  Nanoseconds others = 0;  // the newest good stamp of the other streams
  for (int s = 0; s < kTriadStreamCount; ++s) {
    if (s != stream && timelines_[s].started()) others = std::max(others, timelines_[s].last());
  }
  const StampVerdict verdict = timelines_[stream].check(stamp, others);
  if (!rejects_[stream].admits(verdict)) return false;
  if (verdict == StampVerdict::kNewTimeline) {
    restart();
    for (int s = 0; s < kTriadStreamCount; ++s) {
      if (s != stream) timelines_[s].expectJumpBack(kFollowGiveUp);
    }
  }
  return true;
}

void TriadCalibration::restart() {
  ++restarts_;
  for (int i = 0; i < 3; ++i) {
    sessions_[i] = makeSession(i);
    waves_[i].clear();
    wave_blocks_[i] = BlockMean();
    slot_records_[i].clear();
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

void TriadCalibration::addToBlock(BlockMean* block, Nanoseconds stamp, double value, double rate, StampedSeries* out,
                                  std::vector<double>* rates) const {
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

std::string TriadCalibration::fixtureDrops() const {
  const TriadStreamRejects& r = rejects_[kFixtureStream];
  if (r.total() == 0) return "";
  return " (" + std::to_string(r.total()) + " fixture records were dropped: " + std::to_string(r.bad_value) +
         " orientation not a rotation, " + std::to_string(r.stamp_jump + r.out_of_order + r.bad_stamp) + " bad stamp)";
}

std::array<GyroParameters, 3> TriadCalibration::fitAxes(TriadOutcome* o) const {
  std::array<GyroParameters, 3> params = priors_;
  for (int i = 0; i < 3; ++i) {
    o->axes[i] = sessions_[i]->finish();
    bool vertical_somewhere = false;
    for (const FixtureRecord& f : fixtures_)
      vertical_somewhere = vertical_somewhere || (f.locked && verticalSign(f, i) != 0);
    const std::string axis = o->axis_names[i];
    if (!vertical_somewhere) {
      o->gate("axis_" + axis, false, 0.0, 1.0,
              "no locked position put axis " + axis + " along the table axis: add a position " + alongTableAxis(i) +
                  " (axis " + axis + " up or down) with dual-rate plateaus" + fixtureDrops());
      continue;
    }
    o->gate("axis_" + axis, o->axes[i].accepted, o->axes[i].accepted ? 1.0 : 0.0, 1.0,
            o->axes[i].accepted ? "K(theta) and D(theta) of axis " + axis + " from its dual-rate plateaus"
                                : "axis " + axis + ": " + o->axes[i].reason);
    if (o->axes[i].accepted) params[i] = o->axes[i].parameters;
  }
  return params;
}

void TriadCalibration::measureTilts(TriadOutcome* o) const {
  const EarthRateSettings& earth = priors_[0].earth_rate;
  const double horizontal = horizontalEarthRate(earth.latitude);
  for (int i = 0; i < 3; ++i) {
    const CalibrationOutcome& axis = o->axes[i];
    if (unslotted_[i] > 0) {
      o->notes.push_back("axis " + o->axis_names[i] + " pointed along the table axis in more than " +
                         std::to_string(kHorizontalSlots) +
                         " clampings: the Earth's horizontal rate of the later ones (" + std::to_string(unslotted_[i]) +
                         " samples) is not modelled in its D(theta)");
    }
    if (!earth.enabled || axis.scale_factor.empty() || !(horizontal > 0.0)) continue;
    // The coefficients are K0 Omega cos(latitude) times the lean.
    const double scale = axis.scale_factor.front().mean * horizontal;
    for (const HorizontalEarthFit& h : axis.horizontal_earth) {
      const FixtureRecord& fixture = fixtures_[slot_records_[i][h.slot]];
      TriadAxisTilt t;
      t.axis = i;
      t.position = fixture.index;
      t.name = fixture.name;
      t.body_to_table = fixture.body_to_table.toRotationMatrix();
      t.tilt = Eigen::Vector2d(h.cos, h.sin) / scale;
      t.tilt_std = Eigen::Vector2d(h.cos_std, h.sin_std) / std::abs(scale);
      o->tilts.push_back(t);
    }
  }
}

std::vector<TriadLockedPosition> TriadCalibration::lockedPositions(const std::array<GyroParameters, 3>& params) const {
  TriadSeries series;
  for (int i = 0; i < 3; ++i) {
    series.alpha[i] = compensatedAngle(waves_[i], params[i]);
    series.theta[i] = waves_[i];
  }
  series.table = table_;
  series.table_rates = table_rates_;
  const double max_gap = std::max(axis_settings_.plateau.max_gap, 3.0 / settings_.store_rate);
  std::vector<TriadLockedPosition> out;
  for (std::size_t k = 0; k < fixtures_.size(); ++k) {
    if (!fixtures_[k].locked) continue;
    const Nanoseconds to = k + 1 < fixtures_.size() ? fixtures_[k + 1].stamp : std::numeric_limits<Nanoseconds>::max();
    TriadLockedPosition p;
    p.index = fixtures_[k].index;
    p.name = fixtures_[k].name;
    p.body_to_table = fixtures_[k].body_to_table.toRotationMatrix();
    p.table_axis = p.body_to_table.transpose() * Eigen::Vector3d::UnitZ();
    p.samples = positionSamples(series, fixtures_[k].stamp, to, axis_settings_.plateau, max_gap);
    out.push_back(std::move(p));
  }
  return out;
}

TriadOutcome TriadCalibration::finish() const {
  TriadOutcome o;
  o.axis_names = prior_triad_.axes;
  o.triad = prior_triad_;
  noteRejects(&o);
  const std::array<GyroParameters, 3> params = fitAxes(&o);  // stage 1
  measureTilts(&o);
  // What stages 2 and 3 measure in each locked position: the axes' responses, the rests.
  const double latitude = priors_[0].earth_rate.enabled ? priors_[0].earth_rate.latitude : 0.0;
  for (const TriadLockedPosition& position : lockedPositions(params)) {
    measureResponses(position, settings_, &o);
    measureRests(position, latitude, settings_, &o);
  }
  if (!fitAxisDirections(settings_, fixtureDrops(), &o)) {  // stage 2
    o.decide();
    return o;
  }
  for (TriadAxisTilt& t : o.tilts) {
    // The lean A's row gives in the position's logged orientation, against stage 1's.
    const Eigen::Vector3d in_table = t.body_to_table * o.body_to_axis.row(t.axis).transpose();
    t.from_directions = in_table.head<2>() / in_table.norm();
    t.from_directions_known = true;
  }
  estimateBodyBias(settings_, &o);  // stage 3
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
