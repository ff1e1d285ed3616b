#include "hrg_gyro/core/calibration/calibration_session.h"

#include <algorithm>
#include <utility>

#include "hrg_gyro/core/common/number_format.h"

namespace hrg_gyro {
namespace core {
namespace {

// The two streams reach a live calibrator through different queues and, under accelerated sim time,
// may be tens of seconds of data apart: wave samples wait up to kMaxWait for the rotation's stream,
// and rotation history reaches kMaxWait back from both streams' newest stamps. Both buffers are
// bounded by count as well, so memory stays constant whatever happens.
constexpr double kMaxWait = 60.0;  // s of stamps
constexpr std::size_t kMaxPending = 200000;
constexpr std::size_t kMaxHistory = 400000;
// rad: the angle a good record may differ from the last good one beyond max_rate * dt (reporting
// jitter between the angle and the stamp).
constexpr double kAngleSlack = 0.01;
// Scatter is named as the cause of a refusal when at least this many (and this share) of the plateau
// breaks were spurious: the judged rate left the tolerance and came straight back. A real rate change
// (a ramp) breaks plateaus too, but its rate does not come back.
constexpr std::uint64_t kMinSpuriousBreaks = 10;
constexpr double kSpuriousShare = 0.2;

// Gates that fail when too few wave samples landed on settled plateaus, and (with_coverage) the
// coverage gate, which fails too when plateaus are broken into pieces none of which sweeps theta.
bool refusedForLackOfPlateaus(const CalibrationOutcome& o, bool with_coverage) {
  for (const GateResult& g : o.gates) {
    if (g.passed) continue;
    if (g.name == "samples" || g.name == "plateau_groups" || g.name == "data" || g.name == "steps" ||
        g.name == "dwell_time" || (with_coverage && g.name == "coverage")) {
      return true;
    }
  }
  return false;
}

std::string percent(double fraction) { return formatShort(100.0 * fraction, 2) + " %"; }

TableClockOffsetSettings offsetSettings(const TableClockSettings& c) {
  TableClockOffsetSettings s;
  s.guard = c.max_offset;  // an offset up to the largest accepted is measured without bias
  return s;
}

StampRegulariserSettings stampSettings(const TableClockSettings& c) {
  StampRegulariserSettings s;
  s.enabled = c.regularise;
  s.window = c.window;
  s.max_jitter = c.max_jitter;
  return s;
}
std::string seconds(double s) { return formatShort(s, 3) + " s"; }

}  // namespace

CalibrationSession::CalibrationSession(const CalibrationSettings& settings, const GyroParameters& prior)
    : settings_(settings),
      prior_(prior),
      method_(makeCalibrationMethod(settings, prior)),
      detector_(settings.plateau),
      rotation_(kMaxHistory + 1),
      pending_(kMaxPending + 1),
      regulariser_(stampSettings(settings.table_clock)),
      clock_offset_(offsetSettings(settings.table_clock)),
      rotation_timeline_(settings.stampRule()),
      wave_timeline_(settings.stampRule()) {}

bool CalibrationSession::plausible(Nanoseconds stamp, double angle, double rate) {
  if (!std::isfinite(rate) || std::abs(rate) > settings_.plateau.max_rate) {
    ++counters_.rejected.bad_rate;
    return false;
  }
  // A NaN angle before any finite one: the stream does not log the angle (rate-only).
  if (std::isnan(angle) && !detector_.angleLogged()) return true;
  if (!std::isfinite(angle)) {
    ++counters_.rejected.bad_angle;
    return false;
  }
  if (has_last_good_ && std::isfinite(last_good_angle_) && stamp > last_good_stamp_) {
    const double reach = settings_.plateau.max_rate * toSeconds(stamp - last_good_stamp_) + kAngleSlack;
    // A few in a row: a glitch. More than jump_persist: the table's angle really is elsewhere
    // (the good record kept last was the glitch, or the encoder was re-zeroed); take the new one.
    if (std::abs(angle - last_good_angle_) > reach && ++bad_angle_run_ <= settings_.jump_persist) {
      ++counters_.rejected.bad_angle;
      return false;
    }
  }
  bad_angle_run_ = 0;
  return true;
}

bool CalibrationSession::addRotationRecord(Nanoseconds stamp, double angle, double rate, std::uint64_t sequence) {
  ++counters_.rotation_records;
  ++counters_.rotation_records_total;
  // The table's clock first: a known offset, then the line through a fixed-rate log's stamps (a
  // glitched stamp comes back as it was, and is dropped below like any other).
  // (A precession loop's state is stamped by the gyro's own driver: nothing to correct.)
  if (stamp > 0 && !traitsOf(settings_.method).virtual_rotation) {
    stamp -= toNanoseconds(settings_.table_clock.offset);
    stamp = regulariser_.regularise(stamp, sequence);
  }
  // Values first: a glitched record must not move the stamp reference either.
  if (stamp > 0 && !plausible(stamp, angle, rate)) return false;
  switch (rotation_timeline_.check(stamp, wave_timeline_.last())) {
    case StampVerdict::kNext:
    case StampVerdict::kResumedAhead:  // a gap: the plateau detector sees it
      break;
    case StampVerdict::kNewTimeline:
      restart();
      wave_timeline_.expectJumpBack(kMaxWait);
      counters_.rotation_records = 1;
      break;
    case StampVerdict::kNonPositive:
      ++counters_.rejected.bad_stamp;
      return false;
    case StampVerdict::kDuplicate:
      ++counters_.rejected.duplicate;
      return false;
    case StampVerdict::kBehind:
      ++counters_.rejected.out_of_order;
      return false;
    case StampVerdict::kJumpedBack:
    case StampVerdict::kJumpedAhead:
      ++counters_.rejected.stamp_jump;
      return false;
  }
  has_last_good_ = true;
  last_good_stamp_ = stamp;
  if (std::isfinite(angle)) last_good_angle_ = angle;

  judged_.clear();
  detector_.add(stamp, angle, rate, &judged_);
  for (const PlateauRecord& r : judged_) rotation_.push_back(r);
  drain();
  // Keep history for waiting samples and for wave samples that lag behind this stream.
  Nanoseconds keep_from = std::min(stamp, last_wave_stamp_ > 0 ? last_wave_stamp_ : stamp);
  if (!pending_.empty()) keep_from = std::min(keep_from, pending_.front().stamp);
  keep_from -= toNanoseconds(kMaxWait);
  while (rotation_.size() > 2 && (rotation_[1].stamp < keep_from || rotation_.size() > kMaxHistory)) {
    rotation_.pop_front();
  }
  return true;
}

void CalibrationSession::restart() {
  const RotationRecordRejects rejected = counters_.rejected;
  const std::uint64_t restarts = counters_.restarts + 1;
  const std::uint64_t out_of_order = counters_.out_of_order;
  const std::uint64_t wave_jumps = counters_.wave_jumps;
  const std::uint64_t rotation_records_total = counters_.rotation_records_total;
  method_ = makeCalibrationMethod(settings_, prior_);
  if (horizontal_slots_ > 0) method_->modelHorizontalEarthRate(horizontal_slots_);
  detector_ = PlateauDetector(settings_.plateau);
  regulariser_ = TableStampRegulariser(stampSettings(settings_.table_clock));
  clock_offset_ = TableClockOffsetEstimator(offsetSettings(settings_.table_clock));
  rotation_.clear();
  pending_.clear();
  counters_ = SessionCounters();
  counters_.rejected = rejected;
  counters_.restarts = restarts;
  counters_.out_of_order = out_of_order;
  counters_.wave_jumps = wave_jumps;
  counters_.rotation_records_total = rotation_records_total;
  bad_angle_run_ = 0;
  has_last_good_ = false;
  last_good_stamp_ = 0;
  last_good_angle_ = NAN;
  last_wave_stamp_ = 0;
  last_generator_stamp_ = 0;
  generator_ended_ = false;
  quadrature_sum_ = 0.0;
  quadrature_count_ = 0;
}

void CalibrationSession::addWave(Nanoseconds stamp, double theta, double frequency, double quadrature_ratio) {
  ++counters_.wave;
  switch (wave_timeline_.check(stamp, rotation_timeline_.last())) {
    case StampVerdict::kNext:
    case StampVerdict::kResumedAhead:
      break;
    case StampVerdict::kNewTimeline:
      restart();
      rotation_timeline_.expectJumpBack(kMaxWait);
      counters_.wave = 1;
      break;
    case StampVerdict::kJumpedBack:
    case StampVerdict::kJumpedAhead:
      ++counters_.wave_jumps;
      return;
    case StampVerdict::kNonPositive:
    case StampVerdict::kDuplicate:
    case StampVerdict::kBehind:
      ++counters_.out_of_order;
      return;
  }
  if (std::isfinite(quadrature_ratio)) {
    quadrature_sum_ += std::abs(quadrature_ratio);
    ++quadrature_count_;
  }
  last_wave_stamp_ = stamp;
  pending_.push_back({stamp, theta, frequency});
  // A rotation stream that stopped (or never started) must not make the queue grow without bound.
  while (!pending_.empty() && (pending_.size() > kMaxPending || toSeconds(stamp - pending_.front().stamp) > kMaxWait)) {
    ++counters_.unsynchronized;
    pending_.pop_front();
  }
  drain();
}

void CalibrationSession::generatorSweepEnded() { generator_ended_ = last_generator_stamp_ > 0; }

void CalibrationSession::addGeneratorPair(Nanoseconds stamp, const ChannelVector& raw, const ChannelVector& reference) {
  last_generator_stamp_ = std::max(last_generator_stamp_, stamp);
  method_->addGeneratorPair(raw, reference);
  ++counters_.used;
}

void CalibrationSession::drain() {
  while (!pending_.empty() && !rotation_.empty() && pending_.front().stamp <= rotation_.back().stamp) {
    classify(pending_.front());
    pending_.pop_front();
  }
}

bool CalibrationSession::modelHorizontalEarthRate(int slots, std::function<void(PlateauSample*)> tag) {
  if (!method_->modelHorizontalEarthRate(slots)) return false;
  horizontal_slots_ = slots;
  horizontal_tag_ = std::move(tag);
  return true;
}

void CalibrationSession::classify(const WaveRecord& w) {
  // The last state at or before the sample and the first at or after it.
  const std::size_t after =
      rotation_.lowerBound(w.stamp, [](const PlateauRecord& r, Nanoseconds t) { return r.stamp < t; });
  if (after == rotation_.size() || (after == 0 && rotation_[0].stamp != w.stamp)) {
    ++counters_.unsynchronized;
    return;
  }
  const PlateauRecord& b = rotation_[after];
  const PlateauRecord& a = b.stamp == w.stamp ? b : rotation_[after - 1];
  if (toSeconds(b.stamp - a.stamp) > settings_.plateau.max_gap) {
    ++counters_.unsynchronized;
    return;
  }
  PlateauSample s;
  s.stamp = w.stamp;
  s.theta = w.theta;
  s.frequency = w.frequency;
  s.plateau = b.plateau;
  const double span = toSeconds(b.stamp - a.stamp);
  const double f = span > 0.0 ? toSeconds(w.stamp - a.stamp) / span : 0.0;
  s.rotation_angle = a.angle + f * (b.angle - a.angle);
  s.rotation_rate = a.rate + f * (b.rate - a.rate);
  s.angle_logged = a.angle_logged && b.angle_logged;
  s.angle_smooth_error = regularisedAngleError(s.rotation_rate);
  const bool settled = a.plateau.id == b.plateau.id && a.plateau.settled;
  // Every sample with the table around it, ramps included: the changes of rate show the clocks' offset.
  clock_offset_.add(w.stamp, w.theta, s.rotation_angle, s.rotation_rate, b.plateau.id, b.plateau.rate, settled);
  if (!settled) {
    ++counters_.unsettled;
    return;
  }
  if (horizontal_tag_) horizontal_tag_(&s);
  method_->addSample(s);
  ++counters_.used;
}

bool CalibrationSession::shouldFinish() const {
  if (settings_.auto_finish_idle <= 0.0 || !method_->complete()) return false;
  if (traitsOf(settings_.method).uses_generator_pairs) return generator_ended_;
  if (rotation_.empty()) return false;
  const PlateauRecord& last = rotation_.back();
  return last.plateau.is_static && toSeconds(last.stamp - last.plateau.start) >= settings_.auto_finish_idle;
}

std::string CalibrationSession::plateauDiagnosis(bool* names_a_cause) const {
  bool named = true;
  if (!names_a_cause) names_a_cause = &named;
  *names_a_cause = true;
  const SessionCounters& c = counters_;
  const PlateauSettings& ps = settings_.plateau;
  const PlateauStatistics st = detector_.statistics();
  const std::string stream = traitsOf(settings_.method).virtual_rotation ? "precession state" : "turntable";
  if (c.rotation_records == 0) {
    return "no " + stream + " record arrived" +
           (c.rejected.total() > 0 ? " that was not a glitch (" + std::to_string(c.rejected.total()) + " dropped)"
                                   : std::string()) +
           ": check the " + stream + " stream";
  }
  if (c.wave == 0) {
    return stream + " records arrived without the wave (" + std::to_string(c.rotation_records) + " " + stream +
           " records, no wave sample)";
  }
  if (c.unsynchronized > c.used + c.unsettled) {
    return std::to_string(c.unsynchronized) + " of " + std::to_string(c.wave) + " wave samples had no " + stream +
           " record around their stamp: the two streams' stamps do not overlap, or the " + stream +
           " records are more than plateau/max_gap (" + seconds(ps.max_gap) + ") apart";
  }
  if (st.scatter_blocks > 0 && st.spurious_breaks >= kMinSpuriousBreaks &&
      st.spurious_breaks >= kSpuriousShare * st.breaks) {
    const double tolerance = (ps.rate_tolerance + ps.relative_tolerance * st.typical_rate) / st.typical_rate;
    const std::string against =
        " against a plateau tolerance of " + percent(tolerance) + " at " + formatShort(st.typical_rate, 3) + " rad/s";
    if (ps.smoothing_span <= 0.0) {
      return "reported rate scatter " + percent(st.reported_scatter) + " hides the plateaus (" + against.substr(1) +
             ", judged record by record as plateau/smoothing_span is 0); " +
             (detector_.angleLogged() ? "set plateau/smoothing_span" : "log the angle, set plateau/smoothing_span") +
             " or raise plateau/relative_tolerance";
    }
    if (detector_.angleLogged()) {
      return "the table angle's slope over plateau/smoothing_span (" + seconds(ps.smoothing_span) + ") scatters by " +
             percent(st.judged_scatter) + against + " (reported rate: " + percent(st.reported_scatter) +
             "); lengthen plateau/smoothing_span or raise plateau/relative_tolerance";
    }
    return "reported rate scatter " + percent(st.reported_scatter) + " (" + percent(st.judged_scatter) +
           " averaged over plateau/smoothing_span, " + seconds(ps.smoothing_span) + ")" + against +
           " hides the plateaus; log the angle, lengthen plateau/smoothing_span or raise plateau/relative_tolerance";
  }
  const bool needs_motion = settings_.method != CalibrationMethodKind::kStep;
  const double longest = needs_motion ? st.longest_moving : st.longest;
  if (longest < ps.settle_time) {
    return std::string("no settled plateau") + (needs_motion ? " at a moving rate" : "") +
           ": the rate never stayed within tolerance for plateau/settle_time (" + seconds(ps.settle_time) +
           "); the longest plateau lasted " + seconds(longest);
  }
  *names_a_cause = false;
  return std::to_string(c.unsettled) + " of " + std::to_string(c.wave) +
         " wave samples fell outside settled plateaus; the table was on settled plateaus for " +
         seconds(st.settled_moving) + " moving and " + seconds(st.settled_static) + " at rest (" +
         std::to_string(st.plateaus) + " plateaus started)";
}

double CalibrationSession::regularisedAngleError(double rate) const {
  // A line through N stamps of jitter J is off by about 2 J / sqrt(N) at its newest end: that times
  // the rate is what the regularised stamps leave on the angle, smooth over the line's window.
  const TableStampStatistics& st = regulariser_.statistics();
  if (!st.fixed_rate) return 0.0;
  const double records = std::max<double>(1.0, static_cast<double>(regulariser_.lineRecords()));
  return rate * rate * st.jitter * st.jitter * 4.0 / records;
}

void CalibrationSession::reportTableClock(CalibrationOutcome* o) const {
  TableClockReport& c = o->table_clock;
  c.measured = true;
  c.configured_offset = settings_.table_clock.offset;
  c.stamps = regulariser_.statistics();
  // The offset is measured with the model the run found (the prior's where it found none).
  const bool fitted = !o->scale_factor.empty() && o->scale_factor[0].ok && !o->drift.empty() && o->drift[0].ok &&
                      o->frequency_nodes.empty();
  const HarmonicModel k = fitted ? toModel(o->scale_factor[0]) : prior_.scale_factor;
  const HarmonicModel d = fitted ? toModel(o->drift[0]) : prior_.drift;
  c.offset = clock_offset_.estimate(k, d, prior_.earth_rate.verticalRate());
  if (!c.stamps.note.empty()) o->notes.push_back("table stamps used as logged: " + c.stamps.note);
  if (c.stamps.clock_steps > 0) {
    o->notes.push_back("the table's clock stepped " + std::to_string(c.stamps.clock_steps) +
                       " time(s): its stamps were put on a new line after each step");
  }
  if (!c.offset.estimated) {
    o->notes.push_back("table clock offset not measured: " + c.offset.note);
    return;
  }
  // A table clock running at another rate than the gyro's stretches the table angle against the
  // gyro's time, and K with it (K measured = K (1 + rate error)): undone, its uncertainty added to K0's.
  if (fitted && c.offset.rate_estimated && !c.offset.changed && c.stamps.clock_steps == 0) {
    const double scale = 1.0 / (1.0 + c.offset.rate_error);
    HarmonicFitResult& kf = o->scale_factor[0];
    kf.mean *= scale;
    for (double& v : kf.cos) v *= scale;
    for (double& v : kf.sin) v *= scale;
    kf.mean_std = std::hypot(kf.mean_std * scale, kf.mean * c.offset.rate_error_std);
    o->parameters.scale_factor = toModel(kf);
    c.k_scaled = scale;
    o->notes.push_back("K divided by 1 + " + formatShort(c.offset.rate_error, 3) +
                       " for the table clock's rate against the gyro's (measured from the offsets' drift, +- " +
                       formatShort(c.offset.rate_error_std, 2) + ")");
  }
  const TableClockSettings& ts = settings_.table_clock;
  const double worst = std::abs(c.offset.offset) + 3.0 * c.offset.offset_std;
  const std::string measured = "the table's stamps are " + formatShort(1e3 * c.offset.offset, 3) + " +- " +
                               formatShort(1e3 * c.offset.offset_std, 2) + " ms " +
                               (c.offset.offset >= 0.0 ? "behind" : "ahead of") + " the gyro's (" + c.offset.note + ")";
  // Samples are judged settled by the table's stamps: an offset near the settling time would let a
  // sample of a ramp count on a plateau.
  const bool passed = worst <= ts.max_offset;
  o->gate("table_clock", passed, worst, ts.max_offset,
          passed ? measured
                 : measured +
                       "; beyond table_clock/max_offset the plateaus are judged on a shifted timeline: put "
                       "both on one clock, or set table_clock/offset to " +
                       formatShort(c.configured_offset + c.offset.offset, 4) + " s and calibrate again");
  o->decide();
}

CalibrationOutcome CalibrationSession::finish() const {
  CalibrationOutcome o = method_->finish(prior_);
  bool names_a_cause = false;
  const std::string cause =
      o.accepted || traitsOf(settings_.method).uses_generator_pairs ? std::string() : plateauDiagnosis(&names_a_cause);
  // A coverage shortfall is put down to the plateaus only when the session found a cause.
  if (!cause.empty() && refusedForLackOfPlateaus(o, names_a_cause)) {
    // Name the cause first: the method's own gate says how few samples, this says why.
    o.gates.insert(o.gates.begin(), {"plateaus", false, static_cast<double>(counters_.used),
                                     static_cast<double>(settings_.gates.min_samples), cause});
    o.reason = "plateaus: " + cause + " (" + o.reason + ")";
  }
  o.quadrature_ratio = quadrature_count_ > 0 ? quadrature_sum_ / quadrature_count_ : 0.0;
  // A precession loop's state is on the gyro's clock: no table clock to measure.
  const CalibrationMethodTraits& traits = traitsOf(settings_.method);
  if (!traits.uses_generator_pairs && !traits.virtual_rotation && counters_.rotation_records_total > 0)
    reportTableClock(&o);
  diagnose(&o, prior_.correction);
  o.rotation_records = counters_.rotation_records_total;
  o.rotation_rejected = counters_.rejected;
  o.restarts = counters_.restarts;
  if (counters_.rejected.total() > 0) {
    const RotationRecordRejects& r = counters_.rejected;
    o.notes.push_back(std::to_string(r.total()) + " glitched " +
                      (traits.virtual_rotation ? "precession states" : "turntable records") + " dropped (" +
                      std::to_string(r.bad_rate) + " bad rate, " + std::to_string(r.bad_angle) + " bad angle, " +
                      std::to_string(r.bad_stamp) + " zero stamp, " + std::to_string(r.duplicate) + " duplicate, " +
                      std::to_string(r.out_of_order) + " out of order, " + std::to_string(r.stamp_jump) +
                      " stamp jump)");
  }
  if (counters_.wave_jumps > 0) {
    o.notes.push_back(std::to_string(counters_.wave_jumps) +
                      " wave samples whose stamp jumped (back or ahead: a glitch) were dropped");
  }
  if (counters_.restarts > 0) {
    o.notes.push_back("the stamps went back for good " + std::to_string(counters_.restarts) +
                      " time(s) (bag loop): the run restarted from the prior");
  }
  if (counters_.unsynchronized > 0) {
    o.notes.push_back(std::to_string(counters_.unsynchronized) + " wave samples had no " +
                      (traits.virtual_rotation ? "precession" : "turntable") + " state around them and were not used");
  }
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
