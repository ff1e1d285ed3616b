// hrg_bag process: the processor offline. The same core::GyroProcessor and the same message
// conversions as the node, so the output is bit for bit the node's on the same input.
#include <array>
#include <charconv>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <iostream>
#include <memory>
#include <mutex>
#include <vector>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "csv_text.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/processing/precession_watch.h"
#include "hrg_gyro/ros/conversions.h"
#include "process_triad.h"
#include "serial_worker.h"

namespace hrg_gyro {
namespace {

using bag_tools::CsvText;

const char* verdictName(const core::ProcessorResult& r) {
  switch (r.verdict) {
    case core::SampleVerdict::kAccepted:
      return "accepted";
    case core::SampleVerdict::kFirst:
      return "first";
    case core::SampleVerdict::kRejectedValue:
      return "rejected_value";
    case core::SampleVerdict::kRejectedStamp:
      return "rejected_stamp";
    case core::SampleVerdict::kDuplicate:
      return "duplicate";
    case core::SampleVerdict::kOutOfOrder:
      return "out_of_order";
    case core::SampleVerdict::kRejectedJump:
      return "rejected_jump";
    case core::SampleVerdict::kStampJump:
      return "stamp_jump";
  }
  return "unknown";
}

// The numbers of one CSV row, kept as they are until a formatter thread formats them.
struct CsvRow {
  std::uint32_t sec, nsec, seq;
  const char* status;
  bool has_output, has_wave;
  double dt, dtheta, dalpha, dalpha_earth_fixed, rate, theta_mid, frequency, scale_factor, drift;  // has_output
  std::uint32_t rejected_before;
  std::uint8_t flags;
  double alpha;  // meaningful when has_wave
  double theta, amplitude, quadrature, phase;
};

// The CSV output of process: rows are collected in batches, and two background threads format
// alternate batches (formatting costs about twice what reading does) and write them in order.
class CsvOutput {
 public:
  explicit CsvOutput(std::ostream& out) : out_(out) { rows_ = takeBatch(); }
  /// An abandoned output (an error elsewhere): a formatter waiting for its turn gives up.
  ~CsvOutput() {
    std::lock_guard<std::mutex> lock(mutex_);
    failed_ = true;
    written_turn_.notify_all();
  }
  CsvOutput(const CsvOutput&) = delete;
  CsvOutput& operator=(const CsvOutput&) = delete;
  CsvRow& next() {
    rows_->emplace_back();
    return rows_->back();
  }
  void endRow() {
    if (rows_->size() >= kBatch) submit();
  }
  /// Formats and writes the rest; rethrows what a batch threw.
  void finish() {
    submit();
    for (Formatter& f : formatters_) f.worker.finish();
  }

 private:
  static constexpr std::size_t kBatch = 4096;
  struct Formatter {
    CsvText text;  // used by its worker only
    bag_tools::SerialWorker worker{1};
  };

  std::unique_ptr<std::vector<CsvRow>> takeBatch() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (free_.empty()) {
      auto batch = std::make_unique<std::vector<CsvRow>>();
      batch->reserve(kBatch);
      return batch;
    }
    std::unique_ptr<std::vector<CsvRow>> batch = std::move(free_.back());
    free_.pop_back();
    return batch;
  }

  void submit() {
    if (rows_->empty()) return;
    const std::uint64_t index = submitted_++;
    Formatter& f = formatters_[index % 2];
    std::vector<CsvRow>* batch = rows_.release();
    rows_ = takeBatch();
    f.worker.submit([this, &f, batch, index] {
      std::unique_ptr<std::vector<CsvRow>> rows(batch);
      std::exception_ptr error;
      try {
        f.text.clear();
        for (const CsvRow& r : *rows) format(r, &f.text);
      } catch (...) {
        error = std::current_exception();
      }
      // Written in batch order; after a failure (whose worker drops its later batches) nothing more
      // is written and nobody waits for a turn that will not come.
      std::unique_lock<std::mutex> lock(mutex_);
      written_turn_.wait(lock, [&] { return next_to_write_ == index || failed_; });
      if (!error && !failed_) {
        try {
          out_.write(f.text.data(), static_cast<std::streamsize>(f.text.size()));
        } catch (...) {
          error = std::current_exception();
        }
      }
      ++next_to_write_;
      if (error) failed_ = true;
      rows->clear();
      free_.push_back(std::move(rows));
      written_turn_.notify_all();
      if (error) std::rethrow_exception(error);
    });
  }

  static void format(const CsvRow& r, CsvText* text) {
    const bool o = r.has_output, w = r.has_wave;
    text->beginRow();
    text->stamp(r.sec, r.nsec);
    text->integer(r.seq);
    text->text(r.status);
    text->number(r.dt, o);
    text->number(r.dtheta, o);
    text->number(r.dalpha, o);
    text->number(r.dalpha_earth_fixed, o);
    text->number(r.alpha, w);
    text->number(r.rate, o);
    text->number(r.theta_mid, o);
    text->number(r.frequency, o);
    text->number(r.scale_factor, o);
    text->number(r.drift, o);
    if (o) {
      text->integer(r.rejected_before);
      text->integer(r.flags);
    } else {
      text->text("");
      text->text("");
    }
    text->number(r.theta, w);
    text->number(r.amplitude, w);
    text->number(r.quadrature, w);
    text->number(r.phase, w);
    text->endRow();
  }

  std::ostream& out_;
  std::mutex mutex_;  // guards free_, next_to_write_ and failed_
  std::condition_variable written_turn_;
  std::vector<std::unique_ptr<std::vector<CsvRow>>> free_;
  std::uint64_t next_to_write_ = 0, submitted_ = 0;
  bool failed_ = false;
  std::unique_ptr<std::vector<CsvRow>> rows_;
  std::array<Formatter, 2> formatters_;  // last: their threads stop first
};

struct ProcessOptions {
  std::string bag, params, out, csv, frame_id = "gyro_link", compression = "lz4";
  double precession_hold = core::PrecessionWatchSettings().hold;  ///< s, the node's ~precession_hold
  bag_tools::GyroTopics topics;
  core::ProcessorConfig processor;
  bag_tools::TriadOptions triad;
};

// One input sample's messages and row.
struct ProcessedSample {
  ros::Time stamp;
  std::uint32_t seq = 0;
  const char* status = "";
  bool has_wave = false, has_output = false;
  double alpha = 0.0;
  WaveState wave;
  GyroOutput output;
};

// Where the processed samples go: the output bag (/wave, /output) and the CSV, each a temporary until
// commit(). A dry run has neither and only counts.
class ProcessOutputs {
 public:
  explicit ProcessOutputs(const ProcessOptions& o) {
    using bag_tools::OutputBag;
    using bag_tools::OutputText;
    if (!o.out.empty()) out_ = std::make_unique<OutputBag>(o.out, o.compression);
    if (!o.csv.empty()) {
      csv_file_ = std::make_unique<OutputText>(o.csv);
      csv_file_->stream()
          << "stamp,seq,status,dt,dtheta,dalpha,dalpha_earth_fixed,alpha,rate,theta_mid,frequency,scale_factor,drift,"
             "rejected_before,flags,theta,amplitude,quadrature,phase\n";
      row_ = std::make_unique<CsvOutput>(csv_file_->stream());
    }
  }
  bool dryRun() const { return !out_ && !row_; }
  std::uint64_t precessed() const { return precessed_; }

  void write(const ProcessedSample& x) {
    if (x.has_output && (x.output.flags & core::kFlagPrecessing)) ++precessed_;
    if (dryRun()) return;
    if (out_ && x.has_wave) out_->write(wave_topic_, x.stamp, x.wave);
    if (out_ && x.has_output) out_->write(output_topic_, x.stamp, x.output);
    if (row_) writeRow(x);
  }

  void commit() {
    if (csv_file_) {
      row_->finish();
      csv_file_->commit();
    }
    if (out_) out_->commit();
  }

 private:
  void writeRow(const ProcessedSample& x) {
    const GyroOutput& output = x.output;
    CsvRow& c = row_->next();
    c.sec = x.stamp.sec;
    c.nsec = x.stamp.nsec;
    c.seq = x.seq;
    c.status = x.status;
    c.has_output = x.has_output;
    c.has_wave = x.has_wave;
    c.dt = output.dt;
    c.dtheta = output.dtheta;
    c.dalpha = output.dalpha;
    c.dalpha_earth_fixed = output.dalpha_earth_fixed;
    c.rate = output.rate;
    c.theta_mid = output.theta_mid;
    c.frequency = output.frequency;
    c.scale_factor = output.scale_factor;
    c.drift = output.drift;
    c.rejected_before = output.rejected_before;
    c.flags = output.flags;
    c.alpha = x.alpha;
    c.theta = x.wave.theta;
    c.amplitude = x.wave.amplitude;
    c.quadrature = x.wave.quadrature;
    c.phase = x.wave.phase;
    row_->endRow();
  }

  const std::string wave_topic_ = "/wave", output_topic_ = "/output";
  std::unique_ptr<bag_tools::OutputBag> out_;
  std::unique_ptr<bag_tools::OutputText> csv_file_;
  std::unique_ptr<CsvOutput> row_;
  std::uint64_t precessed_ = 0;
};

// An output waits, as in the node, until the precession state has reached its stamp; the samples
// behind it wait too, so the bag and the CSV keep the input's order.
class PrecessionOrderedWriter {
 public:
  PrecessionOrderedWriter(core::PrecessionWatch* watch, ProcessOutputs* outputs) : watch_(watch), outputs_(outputs) {}

  void add(ProcessedSample& x) {
    if (held_.empty()) {
      // Nothing waits: a sample without an output, or one decided at once, goes straight out.
      core::PrecessionDecision d;
      if (!x.has_output) return outputs_->write(x);
      if (watch_->next(&d)) {
        if (d.flagged()) x.output.flags |= core::kFlagPrecessing;
        return outputs_->write(x);
      }
    }
    held_.push_back(x);
    drain();
  }

  /// Writes the held samples the watch has decided, in order.
  void drain() {
    core::PrecessionDecision d;
    while (!held_.empty()) {
      ProcessedSample& x = held_.front();
      if (x.has_output) {
        if (!watch_->next(&d)) return;
        if (d.flagged()) x.output.flags |= core::kFlagPrecessing;
      }
      outputs_->write(x);
      held_.pop_front();
    }
  }

 private:
  core::PrecessionWatch* watch_;
  ProcessOutputs* outputs_;
  std::deque<ProcessedSample> held_;
};

/// The single gyro's options beyond what the command line checks (the triad's are its own).
void checkSingleGyroOptions(const ProcessOptions& o) {
  using bag_tools::UsageError;
  if (o.params.empty()) {
    throw UsageError("--params is required (the gyro's parameter file; for a triad, --triad with --axis-params)");
  }
  bag_tools::checkProcessorConfig(o.processor);
  try {
    core::PrecessionWatchSettings w;
    w.hold = o.precession_hold;
    w.validate();
  } catch (const core::ConfigError& e) {
    throw UsageError("--precession-hold: " + e.problem());
  }
}

/// The summary on stderr; exit 1 when no sample was accepted.
int reportProcess(const core::ProcessorCounters& c, std::uint64_t outputs, const std::string& precession_topic,
                  const core::PrecessionWatchCounters& p, std::uint64_t precessed) {
  std::cerr << "process: " << c.received << " samples, " << outputs << " outputs, " << c.rejected() << " rejected, "
            << c.gaps << " gaps, " << c.resets << " resets, " << c.stamp_jumps << " stamp jumps dropped\n";
  if (!precession_topic.empty()) {
    std::cerr << "process: precession state from " << precession_topic << ": " << p.states << " records ("
              << p.dropped_states << " dropped), " << precessed << " outputs flagged PRECESSING (" << p.unknown
              << " of them with the state unknown)\n";
  }
  if (c.accepted == 0) {
    // Nothing usable: an output file of rejections only is not a successful run.
    std::cerr << "process: no sample accepted (" << c.non_finite << " non-finite, " << c.no_signal << " no signal, "
              << c.degenerate << " degenerate, " << c.amplitude_out_of_range << " amplitude out of range, "
              << c.zero_stamp << " zero stamp, " << c.duplicate << " duplicate, " << c.out_of_order << " out of order, "
              << c.stamp_jumps << " stamp jumps, " << c.jumps << " jumps)\n";
    return 1;
  }
  return 0;
}

int runProcess(const ProcessOptions& o) {
  using namespace bag_tools;
  if (!o.triad.triad_file.empty()) {
    // As hrg_bag calibrate --method triad: each axis's file with --axis-params.
    if (!o.params.empty()) {
      throw UsageError("--params is a single gyro's; with --triad give each axis's with --axis-params NAME=FILE");
    }
    return runTriadProcess(o.bag, o.out, o.csv, o.compression, o.processor, o.triad);
  }
  checkSingleGyroOptions(o);
  checkOutputPaths({o.bag, o.params}, {o.out, o.csv});
  const auto params = std::make_shared<const core::GyroParameters>(core::loadParameterFile(o.params));
  const std::unique_ptr<rosbag::Bag> in = openBag(o.bag);
  const GyroTopics topics = findTopics(*in, o.topics, true, false, TopicNeed::kIfPresent);
  ProcessOutputs outputs(o);  // both temporaries until the whole bag has been processed
  core::GyroProcessor processor(o.processor, params);
  // The processor node's rule for the precession loop's state (~precession_hold, backward_reset).
  core::PrecessionWatchSettings watch_settings;
  watch_settings.hold = o.precession_hold;
  watch_settings.backward_reset = o.processor.backward_reset;
  core::PrecessionWatch watch(watch_settings);
  PrecessionOrderedWriter writer(&watch, &outputs);
  std::uint64_t output_count = 0;
  ProcessedSample current;
  core::Nanoseconds previous_accepted = 0;  // an output covers (the previous accepted stamp, its own]
  const bool dry_run = outputs.dryRun();    // the summary only
  replayChannels(
      *in, topics.channels, processor,
      [&](const ChannelAmplitudes& msg, const core::ProcessorResult& r) {
        output_count += r.has_output ? 1 : 0;
        ProcessedSample& x = current;
        x.stamp = msg.header.stamp;
        x.has_wave = r.has_wave;
        x.has_output = r.has_output;
        if (r.has_wave) {
          const core::Nanoseconds stamp = toNanoseconds(msg.header.stamp);
          if (r.has_output) watch.addOutput(previous_accepted, stamp);
          previous_accepted = stamp;
        }
        if (!dry_run) {
          x.seq = msg.header.seq;
          x.status = verdictName(r);
          x.alpha = r.alpha;
          x.wave = toWaveMessage(msg, r.wave, o.frame_id);
          x.output = toOutputMessage(x.wave.header, r);
        } else if (r.has_output) {
          x.output.flags = r.flags;
        }
        writer.add(x);
      },
      "process", topics.precession,
      [&](const PrecessionState& state) {
        watch.addState({toNanoseconds(state.header.stamp), state.rate, state.angle});
        writer.drain();
      });
  watch.finish();  // the bag has ended: what still waits is decided with the records it holds
  writer.drain();
  outputs.commit();
  return reportProcess(processor.counters(), output_count, topics.precession, watch.counters(), outputs.precessed());
}

}  // namespace

namespace bag_tools {

Command addProcessCommand(CLI::App& root) {
  auto o = std::make_shared<ProcessOptions>();
  CLI::App* cmd = root.add_subcommand(
      "process", "the processor offline: /wave and /output into a bag, or a CSV; with --triad, three gyros as one IMU");
  cmd->add_option("BAG", o->bag, "input bag with the gyro's channels")->required();
  cmd->add_option("--params", o->params,
                  "parameter file (YAML) of the gyro, as the processor node's (not with --triad)")
      ->check(tools::notEmpty());
  cmd->add_option("--out", o->out, "output bag: /wave and /output, recorded at the input's record time")
      ->check(tools::notEmpty());
  cmd->add_option("--csv", o->csv, "output CSV: one row per input sample with its verdict")->check(tools::notEmpty());
  CLI::Option* frame_id = cmd->add_option("--frame-id", o->frame_id, "frame_id of the written messages")
                              ->check(tools::frameId())
                              ->capture_default_str();
  addCompressionOption(*cmd, &o->compression);
  addTopicOptions(*cmd, &o->topics, false);
  cmd->add_option("--precession-topic", o->topics.precession,
                  "hrg_gyro/PrecessionState topic of a gyro with a precession loop (default: the only one in the "
                  "bag, if any): outputs over which the loop turned the wave are flagged PRECESSING")
      ->check(tools::notEmpty());
  addProcessorOptions(*cmd, &o->processor);
  cmd->add_option("--precession-hold", o->precession_hold,
                  "s, > 0: the processor node's ~precession_hold (how long an output waits for the precession "
                  "state of its stamp)")
      ->transform(tools::finiteNumber())
      ->capture_default_str()
      ->group("Processor limits (the processor node's parameters; same rules)");
  CLI::Option* triad = addTriadOptions(*cmd, &o->triad);
  // The triad's frame is its file's, each axis's channels topic /AXIS/channels.
  triad->excludes(frame_id);
  triad->excludes(cmd->get_option("--channels-topic"));
  cmd->footer(
      "Runs the processor on the bag's channels. Numbers in the CSV are in the shortest form that reads\n"
      "back exactly. With neither --out nor --csv, only the summary (a dry run). When the bag holds the\n"
      "precession loop's state (hrg_gyro/PrecessionState), the outputs over which the loop turned the wave\n"
      "carry FLAG_PRECESSING (16) as the live node's do.\n"
      "Outputs are written to temporaries and renamed over --out/--csv only when complete; an output\n"
      "that is the same file as an input or as the other output is refused.\n"
      "With --triad FILE, the bag holds three gyros' channels, /NAME/channels for each axis of the triad\n"
      "file (or --axis-channels NAME=TOPIC), and --axis-params NAME=FILE gives each axis's parameter file:\n"
      "  hrg_bag process triad.bag --triad triad.yaml --axis-params x=x.yaml --axis-params y=y.yaml \\\n"
      "      --axis-params z=z.yaml --out triad_out.bag --csv triad.csv\n"
      "--out then holds /triad/output (TriadOutput, every triad sample), /imu/data_raw (the samples not\n"
      "flagged GAP or RESET) and each /AXIS/output; --csv one row per triad sample. The numbers are the live\n"
      "processor and triad nodes' bit for bit; stamps an axis never delivered end the output as gaps.\n"
      "Exit 0 success, 1 when no sample was accepted (with --triad: combined), 2 bad usage or unreadable\n"
      "input, 3 an output could not be written (nothing left at its path, an existing file unchanged).");
  return [o] { return runProcess(*o); };
}

}  // namespace bag_tools

}  // namespace hrg_gyro
