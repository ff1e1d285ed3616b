#include "hrg_gyro/core/calibration/field_command_plan.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "hrg_gyro/core/calibration/calibration_outcome.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/resonator/first_order_model.h"

namespace hrg_gyro {
namespace core {

std::vector<PlannedPrecession> fieldCommandPlan(const CalibrationSettings& s) {
  const std::string problem = fieldPlanLengthProblem(s);
  if (!problem.empty()) throw std::invalid_argument("field plan: " + problem);
  std::vector<PlannedPrecession> plan;
  double t = 0.0;
  plan.push_back({t, 0.0});
  t += s.field.rest;
  const double segment = fieldSegmentDuration(s);
  for (const int sign : s.field.directions) {
    plan.push_back({t, sign * s.field.rate});
    t += segment;
  }
  plan.push_back({t, 0.0});
  return plan;
}

double fieldLoopLag(const FieldSettings& field, double rate) {
  if (!field.resonator) return NAN;
  const FieldResonator& r = *field.resonator;
  return precessionLagDrift(r.shell, r.loops, r.drive, rate).peakDeviation();
}

void checkFieldPlan(const CalibrationSettings& s) {
  const std::string problem = fieldPlanLengthProblem(s);
  if (!problem.empty()) throw std::invalid_argument("field plan: " + problem);
  const FieldSettings& f = s.field;
  const double lag = fieldLoopLag(f, f.rate);
  if (lag > f.max_drift_std) {
    throw std::invalid_argument(
        "field/rate " + formatShort(f.rate, 3) + " rad/s: the loops' lag adds up to " + formatShort(lag, 3) +
        " rad/s to D for the gyro of field/resonator, more than field/max_drift_std " +
        formatShort(f.max_drift_std, 3) + " rad/s; the loop_lag gate would refuse the result: command a slower rate");
  }
}

double FieldPlanRun::overdueMargin(const CalibrationSettings& s) {
  return s.plateau.settle_time + s.plateau.smoothing_span + 1.0;
}

namespace {

std::vector<PlannedPrecession> checkedPlan(const CalibrationSettings& settings) {
  checkFieldPlan(settings);
  return fieldCommandPlan(settings);
}

}  // namespace

FieldPlanRun::FieldPlanRun(const CalibrationSettings& settings, std::string self)
    : plan_(checkedPlan(settings)),
      margin_(overdueMargin(settings)),
      self_(std::move(self)),
      needed_("coverage " + formatShort(100 * settings.gates.min_coverage, 3) + " % and " +
              formatShort(settings.field.min_turns, 3) + " turns") {}

void FieldPlanRun::start(const PrecessionReport& report) {
  started_ = true;
  start_ = report.stamp;
  base_commands_ = report.commands;
  last_checked_ = report.stamp;
}

bool FieldPlanRun::nextDue(Nanoseconds now, PlannedPrecession* command) {
  if (!started_ || next_ >= plan_.size()) return false;
  if (toSeconds(now - start_) < plan_[next_].time) return false;
  *command = plan_[next_++];
  sent_rates_.push_back(command->rate);
  return true;
}

void FieldPlanRun::stop() {
  sent_rates_.push_back(0.0);
  next_ = plan_.size();
}

bool FieldPlanRun::end() {
  if (!midway()) return false;
  stop();
  return true;
}

void FieldPlanRun::restart() {
  next_ = 0;
  sent_rates_.clear();
  started_ = false;
  start_ = 0;
  base_commands_ = 0;
  last_checked_ = 0;
}

FieldPlanStep FieldPlanRun::step(const PrecessionReport& report, const std::function<bool()>& driver_listens,
                                 const CalibrationSession& session, Nanoseconds wave_now) {
  FieldPlanStep out;
  // Someone else turns the wave: the run's data are no longer what its plan made them.
  out.foreign = check(report);
  if (!out.foreign.empty()) return out;
  if (!started_) {
    if (!driver_listens()) return out;
    start(report);
  }
  PlannedPrecession p;
  while (nextDue(report.stamp, &p)) out.due.push_back(p);
  // The progress (words) is asked for only once the plan is over.
  if (session.complete() || next_ < plan_.size()) return out;
  out.overdue = overdue(report.stamp, wave_now, session.progress().summary);
  return out;
}

namespace {

bool sameRate(double a, double b) { return std::abs(a - b) <= 1e-12 + FieldPlanRun::kRateTolerance * std::abs(b); }

}  // namespace

std::string FieldPlanRun::check(const PrecessionReport& r) {
  if (!started_ || r.stamp <= last_checked_) return std::string();
  last_checked_ = r.stamp;
  // Until the driver executes a command after the plan began, the rate in force is the one before
  // it (the plan's first command, rate 0, replaces it).
  if (r.commands == base_commands_ || sent_rates_.empty()) return std::string();
  if (!r.source.empty() && r.source != self_) {
    return "the precession loop executed a command from " + r.source + ", not from this calibrator (" + self_ +
           "): " + formatShort(r.rate, 6) + " rad/s in force";
  }
  // The rate in force is the last command's; until the driver has executed as many commands as the
  // run sent, the last may still be on its way and the one before it in force. A count that went
  // back (a restarted driver) says nothing of what it executed.
  const bool went_back = r.commands < base_commands_;
  const double last = sent_rates_.back();
  bool ours = sameRate(r.rate, last);
  if (!ours && !went_back && r.commands - base_commands_ < sent_rates_.size() && sent_rates_.size() >= 2) {
    ours = sameRate(r.rate, sent_rates_.end()[-2]);
  }
  if (!ours) {
    std::string why = "the precession state shows " + formatShort(r.rate, 6) +
                      " rad/s in force, which this run did not command (its last command: " + formatShort(last, 6) +
                      " rad/s)";
    if (went_back) {
      why += "; the driver's command count went back from " + std::to_string(base_commands_) + " to " +
             std::to_string(r.commands) + " (a restarted driver?)";
    }
    return why;
  }
  // A driver that names nobody: a command of the same rate from another node shows in the count only.
  // (A driver that names this calibrator may also have executed its latched command again on reconnecting.)
  if (r.source.empty() && r.commands > base_commands_ && r.commands - base_commands_ > sent_rates_.size()) {
    return "the driver executed " + std::to_string(r.commands - base_commands_) +
           " commands since the plan began and this run sent " + std::to_string(sent_rates_.size()) +
           ": another node commanded the precession loop";
  }
  return std::string();
}

std::string FieldPlanRun::overdue(Nanoseconds state_now, Nanoseconds wave_now, const std::string& progress) const {
  if (!started_ || next_ < plan_.size() || plan_.empty()) return std::string();
  const Nanoseconds end = start_ + toNanoseconds(plan_.back().time);
  const Nanoseconds due = end + toNanoseconds(margin_);
  if (state_now < due) return std::string();
  // The wave of the plan's last segment may still be on its way: wait for that stream too, unless
  // it has stopped.
  if (wave_now < due && state_now < due + toNanoseconds(kWaveStreamWait)) return std::string();
  std::string why = "the plan's last command is " + formatShort(toSeconds(state_now - end), 3) +
                    " s of stream time past and the data are incomplete: " + progress + " (each direction needs " +
                    needed_ + ")";
  if (wave_now == 0) {
    why += "; no wave sample received (is the processor running?)";
  } else if (wave_now < due) {
    why += "; the wave stream stopped " + formatShort(toSeconds(wave_now - start_), 4) + " s into the plan";
  }
  return why;
}

void refuseFieldRun(CalibrationOutcome* o, const std::string& gate, const std::string& message) {
  o->gates.insert(o->gates.begin(), GateResult{gate, false, 1.0, 0.0, message});
  o->reason = gate + ": " + message;
  o->accepted = false;
}

}  // namespace core
}  // namespace hrg_gyro
