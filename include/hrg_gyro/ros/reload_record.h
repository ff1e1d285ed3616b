// What a node's `~reload` service has done with the file it re-reads (the processor's parameter
// file, the triad's file): how many loads and refusals, and why the last one was refused (the
// previous file then stays in force). The service's answer to a refusal, its log line and the
// diagnostics' lines are worded alike for every node.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <std_srvs/Trigger.h>

#include <cstdint>
#include <string>
#include <utility>

namespace hrg_gyro {

class ReloadRecord {
 public:
  /// `node`: the log lines' prefix ("processor"); `kept`: what a refusal keeps ("model", "triad").
  ReloadRecord(std::string node, std::string kept) : node_(std::move(node)), kept_(std::move(kept)) {}

  /// A refused file: counted and its reason kept; `res` answers "kept the previous <kept>: <why>",
  /// and the log has an error. The caller holds the node's lock.
  void refuse(const std::string& why, std_srvs::Trigger::Response* res);
  /// A loaded file: counted, the last refusal forgotten.
  void loaded();

  bool lastRefused() const { return !last_error_.empty(); }
  /// "last reload refused, previous <kept> kept: <why>" (a WARN summary when lastRefused()).
  std::string refusalSummary() const;
  /// The diagnostics' "reloads" and "refused reloads".
  void addCounts(diagnostic_updater::DiagnosticStatusWrapper& stat) const;

 private:
  std::string node_, kept_;
  std::uint64_t loads_ = 0, refusals_ = 0;
  std::string last_error_;
};

}  // namespace hrg_gyro
