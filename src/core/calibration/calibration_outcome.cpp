#include "hrg_gyro/core/calibration/calibration_outcome.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <ctime>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {

void CalibrationOutcome::gate(const std::string& name, bool passed, double value, double limit,
                              const std::string& message) {
  gates.push_back({name, passed, value, limit, message});
  if (!passed && reason.empty()) reason = name + ": " + message;
}

void CalibrationOutcome::decide() {
  accepted = !gates.empty();
  for (const GateResult& g : gates) accepted = accepted && g.passed;
  if (gates.empty() && reason.empty()) reason = "no quality gate was evaluated";
}

namespace {

void emitNumbers(YAML::Emitter& out, const std::vector<double>& v) {
  out << YAML::Flow << YAML::BeginSeq;
  for (double x : v) out << formatDouble(x);
  out << YAML::EndSeq;
}

void emitFit(YAML::Emitter& out, const HarmonicFitResult& f, double frequency) {
  out << YAML::BeginMap;
  out << YAML::Key << "orders" << YAML::Value << YAML::Flow << f.orders;
  if (frequency == frequency) out << YAML::Key << "frequency" << YAML::Value << formatDouble(frequency);
  out << YAML::Key << "mean" << YAML::Value << formatDouble(f.mean);
  out << YAML::Key << "mean_std" << YAML::Value << formatDouble(f.mean_std);
  out << YAML::Key << "cos" << YAML::Value;
  emitNumbers(out, f.cos);
  out << YAML::Key << "cos_std" << YAML::Value;
  emitNumbers(out, f.cos_std);
  out << YAML::Key << "sin" << YAML::Value;
  emitNumbers(out, f.sin);
  out << YAML::Key << "sin_std" << YAML::Value;
  emitNumbers(out, f.sin_std);
  out << YAML::Key << "residual_rms" << YAML::Value << formatDouble(f.residual_rms);
  out << YAML::Key << "points" << YAML::Value << f.points;
  out << YAML::EndMap;
}

}  // namespace

std::string utcNow() {
  char buf[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  return buf;
}

int maxFittedOrder(const std::vector<int>& scale_factor_orders, const std::vector<int>& drift_orders) {
  const std::vector<int> all = mergeOrders(scale_factor_orders, drift_orders);
  return all.empty() ? 2 : all.back();
}

void diagnose(CalibrationOutcome* o, const CorrectionMatrix& correction_in_force) {
  o->diagnosis.clear();
  for (std::size_t i = 0; i < o->scale_factor.size(); ++i) {
    const HarmonicFitResult& k = o->scale_factor[i];
    if (!k.ok) continue;
    const double f = i < o->frequency_nodes.size() ? o->frequency_nodes[i] : NAN;
    o->diagnosis.push_back(diagnoseDefects(k, o->quadrature_ratio, correction_in_force, f));
  }
}

void emitGatesAndNotes(YAML::Emitter& out, const std::vector<GateResult>& gates,
                       const std::vector<std::string>& notes) {
  out << YAML::Key << "gates" << YAML::Value << YAML::BeginSeq;
  for (const GateResult& g : gates) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << g.name;
    out << YAML::Key << "passed" << YAML::Value << g.passed;
    out << YAML::Key << "value" << YAML::Value << formatDouble(g.value);
    out << YAML::Key << "limit" << YAML::Value << formatDouble(g.limit);
    out << YAML::Key << "message" << YAML::Value << YAML::DoubleQuoted << g.message;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "notes" << YAML::Value << YAML::BeginSeq;
  for (const std::string& n : notes) out << YAML::DoubleQuoted << n;
  out << YAML::EndSeq;
}

namespace {

/// K and D: one harmonic fit per frequency node (one without nodes).
void emitFits(YAML::Emitter& out, const CalibrationOutcome& o) {
  for (const char* part : {"scale_factor", "drift"}) {
    const auto& fits = std::string(part) == "scale_factor" ? o.scale_factor : o.drift;
    out << YAML::Key << part << YAML::Value << YAML::BeginSeq;
    for (std::size_t i = 0; i < fits.size(); ++i) {
      emitFit(out, fits[i], i < o.frequency_nodes.size() ? o.frequency_nodes[i] : NAN);
    }
    out << YAML::EndSeq;
  }
}

/// The correction matrix P measured (the correction-matrix method).
void emitCorrection(YAML::Emitter& out, const CalibrationOutcome& o) {
  if (!o.has_correction) return;
  out << YAML::Key << "correction" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "p" << YAML::Value;
  emitNumbers(out, {o.correction.correction.p.begin(), o.correction.correction.p.end()});
  out << YAML::Key << "p_std" << YAML::Value;
  emitNumbers(out, {o.correction.standard_error.begin(), o.correction.standard_error.end()});
  out << YAML::Key << "residual_rms" << YAML::Value << formatDouble(o.correction.residual_rms);
  out << YAML::Key << "condition_number" << YAML::Value << formatDouble(o.correction.condition_number);
  out << YAML::Key << "pairs" << YAML::Value << o.correction.pairs;
  out << YAML::EndMap;
}

/// The rotation's records, the glitches dropped and the restarts.
void emitRotationRecords(YAML::Emitter& out, const CalibrationOutcome& o) {
  // The records of the rotation's stream (the table's; a field run's: the precession loop's states),
  // the glitched ones dropped before the plateau detector, and bag-loop restarts. The keys keep the
  // table's names.
  out << YAML::Key << "turntable_records" << YAML::Value << o.rotation_records;
  if (traitsOf(o.method).virtual_rotation) {
    out << YAML::Comment("precession states (the field method's stream), and their glitches below");
  }
  out << YAML::Key << "turntable_rejected" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "bad_rate" << YAML::Value << o.rotation_rejected.bad_rate;
  out << YAML::Key << "bad_angle" << YAML::Value << o.rotation_rejected.bad_angle;
  out << YAML::Key << "bad_stamp" << YAML::Value << o.rotation_rejected.bad_stamp;
  out << YAML::Key << "duplicate" << YAML::Value << o.rotation_rejected.duplicate;
  out << YAML::Key << "out_of_order" << YAML::Value << o.rotation_rejected.out_of_order;
  out << YAML::Key << "stamp_jump" << YAML::Value << o.rotation_rejected.stamp_jump;
  out << YAML::EndMap;
  out << YAML::Key << "restarts" << YAML::Value << o.restarts;
}

/// The table's clock against the gyro's, when it was measured.
void emitTableClock(YAML::Emitter& out, const CalibrationOutcome& o) {
  if (!o.table_clock.measured) return;
  // The table's clock against the gyro's: stamps regularised from the record count, the offset
  // measured at every change of rate (table stamps minus gyro stamps, after the configured offset).
  const TableClockReport& c = o.table_clock;
  out << YAML::Key << "table_clock" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "configured_offset" << YAML::Value << formatDouble(c.configured_offset) << YAML::Comment("s");
  out << YAML::Key << "regularised" << YAML::Value << c.stamps.fixed_rate;
  if (!c.stamps.note.empty())
    out << YAML::Key << "regularisation_note" << YAML::Value << YAML::DoubleQuoted << c.stamps.note;
  out << YAML::Key << "records" << YAML::Value << c.stamps.records;
  out << YAML::Key << "regularised_records" << YAML::Value << c.stamps.regularised;
  out << YAML::Key << "off_line_records" << YAML::Value << c.stamps.off_line;
  out << YAML::Key << "clock_steps" << YAML::Value << c.stamps.clock_steps;
  out << YAML::Key << "counted_by" << YAML::Value << (c.stamps.used_sequence ? "sequence" : "spacing");
  out << YAML::Key << "log_period" << YAML::Value << formatDouble(c.stamps.period) << YAML::Comment("s");
  out << YAML::Key << "jitter" << YAML::Value << formatDouble(c.stamps.jitter)
      << YAML::Comment("s, rms of the stamps about their line");
  out << YAML::Key << "offset_estimated" << YAML::Value << c.offset.estimated;
  out << YAML::Key << "offset" << YAML::Value << formatDouble(c.offset.offset) << YAML::Comment("s");
  out << YAML::Key << "offset_std" << YAML::Value << formatDouble(c.offset.offset_std) << YAML::Comment("s");
  out << YAML::Key << "offset_spread" << YAML::Value << formatDouble(c.offset.spread) << YAML::Comment("s");
  out << YAML::Key << "offset_changed" << YAML::Value << c.offset.changed;
  out << YAML::Key << "rate_error_estimated" << YAML::Value << c.offset.rate_estimated;
  out << YAML::Key << "rate_error" << YAML::Value << formatDouble(c.offset.rate_error)
      << YAML::Comment("s per s: the table's clock against the gyro's, from the offsets' drift");
  out << YAML::Key << "rate_error_std" << YAML::Value << formatDouble(c.offset.rate_error_std);
  out << YAML::Key << "k_scaled" << YAML::Value << formatDouble(c.k_scaled)
      << YAML::Comment("K was multiplied by this for the clocks' rate difference");
  out << YAML::Key << "offset_note" << YAML::Value << YAML::DoubleQuoted << c.offset.note;
  out << YAML::Key << "transitions" << YAML::Value << YAML::BeginSeq;
  for (const TableClockTransition& t : c.offset.transitions) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "stamp" << YAML::Value << formatDouble(toSeconds(t.stamp));
    out << YAML::Key << "rate_before" << YAML::Value << formatDouble(t.rate_before);
    out << YAML::Key << "rate_after" << YAML::Value << formatDouble(t.rate_after);
    out << YAML::Key << "offset" << YAML::Value << formatDouble(t.offset);
    out << YAML::Key << "offset_noise" << YAML::Value << formatDouble(t.offset_noise);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
}

/// The field method's own numbers, once its fit gave them.
void emitFieldReport(YAML::Emitter& out, const CalibrationOutcome& o) {
  if (!o.field.present) return;
  // The field method: K kept, the virtual rate's realised gain, the drift as the still gyro showed it.
  const FieldReport& f = o.field;
  out << YAML::Key << "field" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "virtual_rate_gain" << YAML::Value;
  emitFit(out, f.virtual_rate_gain, NAN);  // realised over commanded virtual rate, G_v(theta)
  out << YAML::Key << "measured_drift" << YAML::Value;
  emitFit(out, f.measured_drift, NAN);  // rad/s: D + K Omega_s, before the Earth rate's share came off
  out << YAML::Key << "earth_rate" << YAML::Value << formatDouble(f.earth_rate) << YAML::Comment("rad/s, Omega_s");
  out << YAML::Key << "k0_prior" << YAML::Value << formatDouble(f.k0_prior) << YAML::Comment("kept");
  out << YAML::Key << "positive_rate" << YAML::Value << formatDouble(f.positive_rate) << YAML::Comment("rad/s");
  out << YAML::Key << "negative_rate" << YAML::Value << formatDouble(f.negative_rate) << YAML::Comment("rad/s");
  out << YAML::Key << "positive_turns" << YAML::Value << formatDouble(f.positive_turns);
  out << YAML::Key << "negative_turns" << YAML::Value << formatDouble(f.negative_turns)
      << YAML::Comment("full turns of theta");
  out << YAML::Key << "positive_time" << YAML::Value << formatDouble(f.positive_time) << YAML::Comment("s");
  out << YAML::Key << "negative_time" << YAML::Value << formatDouble(f.negative_time) << YAML::Comment("s");
  out << YAML::Key << "excess_scatter" << YAML::Value << formatDouble(f.excess_scatter)
      << YAML::Comment("D's harmonics' standard errors over the white-noise prediction (rms): stillness");
  out << YAML::EndMap;
}

/// The bias trend fitted with K and D, if one was.
void emitBiasTrend(YAML::Emitter& out, const CalibrationOutcome& o) {
  if (o.bias_trend.order <= 0) return;
  // The bias's polynomial in time fitted with K and D: D0(t) = drift.mean + sum_j b_j (t - t_ref)^j.
  const BiasTrendFit& t = o.bias_trend;
  out << YAML::Key << "bias_trend" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "order" << YAML::Value << t.order;
  out << YAML::Key << "coefficients" << YAML::Value;
  emitNumbers(out, t.coefficients);
  out << YAML::Comment("rad/s per s^j, j = 1..order");
  out << YAML::Key << "coefficients_std" << YAML::Value;
  emitNumbers(out, t.stds);
  out << YAML::Key << "reference_stamp" << YAML::Value << formatDouble(toSeconds(t.reference_stamp))
      << YAML::Comment("s: t_ref, where the bias is drift.mean");
  out << YAML::Key << "span" << YAML::Value << formatDouble(t.span) << YAML::Comment("s of data fitted");
  out << YAML::Key << "change_over_span" << YAML::Value << formatDouble(t.coefficients.front() * t.span)
      << YAML::Comment("rad/s: the linear term over the span");
  out << YAML::Key << "k0_inflation" << YAML::Value << formatDouble(t.k0_inflation);
  out << YAML::Key << "k0_correlation" << YAML::Value << formatDouble(t.k0_correlation);
  out << YAML::EndMap;
}

/// The bias's random walk estimated with the dual-rate fit, if it shows.
void emitBiasWalk(YAML::Emitter& out, const CalibrationOutcome& o) {
  const BiasWalkFit& w = o.bias_walk;
  if (!(w.rate_random_walk > 0.0)) return;
  out << YAML::Key << "bias_random_walk" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "rate_random_walk" << YAML::Value << formatDouble(w.rate_random_walk)
      << YAML::Comment("rad/s/sqrt(s), from the blocks' mean residual rates");
  out << YAML::Key << "rate_random_walk_std" << YAML::Value << formatDouble(w.rate_random_walk_std);
  out << YAML::Key << "angle_random_walk" << YAML::Value << formatDouble(w.angle_random_walk)
      << YAML::Comment("rad/sqrt(s), fitted with it");
  out << YAML::Key << "carried" << YAML::Value << w.carried
      << YAML::Comment("the standard errors include what it predicts");
  out << YAML::EndMap;
}

/// The defect diagnosis, one per K fit.
void emitDiagnosis(YAML::Emitter& out, const CalibrationOutcome& o) {
  // Root causes read from the K harmonics (first order, docs/math.md 'Pickoff defects to first
  // order'); see defect_diagnosis.h.
  out << YAML::Key << "diagnosis" << YAML::Value << YAML::BeginSeq;
  for (const DefectDiagnosis& d : o.diagnosis) {
    out << YAML::BeginMap;
    if (std::isfinite(d.frequency)) out << YAML::Key << "frequency" << YAML::Value << formatDouble(d.frequency);
    out << YAML::Key << "valid" << YAML::Value << d.valid;
    out << YAML::Key << "note" << YAML::Value << YAML::DoubleQuoted << d.note;
    out << YAML::Key << "gain_mismatch" << YAML::Value << formatDouble(d.gain_mismatch)
        << YAML::Comment("gc - gs, relative");
    out << YAML::Key << "gain_mismatch_std" << YAML::Value << formatDouble(d.gain_mismatch_std);
    out << YAML::Key << "misplacement_difference" << YAML::Value << formatDouble(d.misplacement_difference)
        << YAML::Comment("dc - ds, rad");
    out << YAML::Key << "misplacement_difference_std" << YAML::Value << formatDouble(d.misplacement_difference_std);
    out << YAML::Key << "pickoff_ratio" << YAML::Value << formatDouble(d.pickoff_ratio) << YAML::Comment("A/d0");
    out << YAML::Key << "pickoff_ratio_std" << YAML::Value << formatDouble(d.pickoff_ratio_std);
    out << YAML::Key << "quadrature_factor" << YAML::Value << formatDouble(d.quadrature_factor);
    out << YAML::Key << "current_p" << YAML::Value;
    emitNumbers(out, {d.current_correction.p.begin(), d.current_correction.p.end()});
    out << YAML::Key << "recommended_p" << YAML::Value;
    emitNumbers(out, {d.recommended_correction.p.begin(), d.recommended_correction.p.end()});
    out << YAML::Key << "recommended_p_std" << YAML::Value;
    emitNumbers(out, {d.recommended_correction_std.begin(), d.recommended_correction_std.end()});
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

/// The rate groups' summaries.
void emitPlateaus(YAML::Emitter& out, const CalibrationOutcome& o) {
  out << YAML::Key << "plateaus" << YAML::Value << YAML::BeginSeq;
  for (const GroupSummary& g : o.plateaus) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "rate" << YAML::Value << formatDouble(g.rate);
    out << YAML::Key << "rate_std" << YAML::Value << formatDouble(g.rate_std);
    out << YAML::Key << "duration" << YAML::Value << formatDouble(g.duration);
    out << YAML::Key << "samples" << YAML::Value << g.samples;
    out << YAML::Key << "coverage" << YAML::Value << formatDouble(g.coverage);
    out << YAML::Key << "turns" << YAML::Value << formatDouble(g.turns);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
}

/// The binned K and D the fits were made on.
void emitBinned(YAML::Emitter& out, const CalibrationOutcome& o) {
  out << YAML::Key << "binned" << YAML::Value << YAML::BeginMap;
  std::vector<double> th, k, d, w;
  for (const BinnedCurvePoint& p : o.binned) {
    th.push_back(p.theta);
    k.push_back(p.k);
    d.push_back(p.d);
    w.push_back(p.weight);
  }
  out << YAML::Key << "theta" << YAML::Value;
  emitNumbers(out, th);
  out << YAML::Key << "k" << YAML::Value;
  emitNumbers(out, k);
  out << YAML::Key << "d" << YAML::Value;
  emitNumbers(out, d);
  out << YAML::Key << "weight" << YAML::Value;
  emitNumbers(out, w);
  out << YAML::EndMap;
}

}  // namespace

std::string emitCalibrationReport(const CalibrationOutcome& o) {
  YAML::Emitter out;
  out << YAML::Comment("hrg_gyro calibration report. K dimensionless, D in rad/s, angles in rad.");
  out << YAML::BeginMap;
  out << YAML::Key << "method" << YAML::Value << nameOf(o.method);
  out << YAML::Key << "accepted" << YAML::Value << o.accepted;
  out << YAML::Key << "reason" << YAML::Value << YAML::DoubleQuoted << o.reason;
  out << YAML::Key << "coverage" << YAML::Value << formatDouble(o.coverage);
  out << YAML::Key << "smoothing_factor" << YAML::Value << formatDouble(o.smoothing_factor);
  out << YAML::Key << "error_bound" << YAML::Value << formatDouble(o.error_bound);
  out << YAML::Key << "nonlinearity_ppm" << YAML::Value << formatDouble(o.nonlinearity_ppm);
  out << YAML::Key << "duration" << YAML::Value << formatDouble(o.duration);
  out << YAML::Key << "samples" << YAML::Value << o.samples;
  if (!o.frequency_nodes.empty()) {
    out << YAML::Key << "frequency_nodes" << YAML::Value;
    emitNumbers(out, o.frequency_nodes);
  }
  emitFits(out, o);
  emitCorrection(out, o);
  out << YAML::Key << "quadrature_ratio" << YAML::Value << formatDouble(o.quadrature_ratio);
  emitRotationRecords(out, o);
  emitTableClock(out, o);
  emitFieldReport(out, o);
  emitBiasTrend(out, o);
  emitBiasWalk(out, o);
  emitDiagnosis(out, o);
  emitPlateaus(out, o);
  emitGatesAndNotes(out, o.gates, o.notes);
  emitBinned(out, o);
  out << YAML::Key << "parameters" << YAML::Value << YAML::Literal
      << (o.accepted ? emitParameters(o.parameters) : std::string("not accepted"));
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace core
}  // namespace hrg_gyro
