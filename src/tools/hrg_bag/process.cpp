// hrg_bag process: the processor offline. The same core::GyroProcessor and the same message
// conversions as the node, so the output is bit for bit the node's on the same input.
#include <charconv>
#include <cstdio>
#include <iostream>
#include <memory>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/ros/conversions.h"
#include "serial_worker.h"

namespace hrg_gyro {
namespace {

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
  }
  return "unknown";
}

// CSV text, appended to one large buffer that is written out in pieces of about a megabyte (no
// per-row stream call, no flush). Numbers in the shortest form that reads back to the same double
// (std::to_chars), several times faster than printf's %.17g and just as exact.
class CsvText {
 public:
  explicit CsvText(std::ostream& out) : out_(out) { text_.reserve(kFlushSize + 4096); }
  void number(double v, bool present = true) {
    separator();
    if (present) append(std::to_chars(scratch_, scratch_ + sizeof scratch_, v).ptr);
  }
  void integer(std::uint64_t v) {
    separator();
    append(std::to_chars(scratch_, scratch_ + sizeof scratch_, v).ptr);
  }
  /// sec.nsec with nine digits after the point, as printf's "%u.%09u".
  void stamp(std::uint32_t sec, std::uint32_t nsec) {
    separator();
    if (nsec >= 1000000000u) {  // not normalised: printf's own form, as many digits as it takes
      append(scratch_ + std::snprintf(scratch_, sizeof scratch_, "%u.%09u", sec, nsec));
      return;
    }
    char* end = std::to_chars(scratch_, scratch_ + sizeof scratch_, sec).ptr;
    *end++ = '.';
    for (int digit = 8; digit >= 0; --digit, nsec /= 10) end[digit] = static_cast<char>('0' + nsec % 10);
    append(end + 9);
  }
  void text(const char* t) {
    separator();
    text_ += t;
  }
  void endRow() {
    text_ += '\n';
    first_ = true;
    if (text_.size() >= kFlushSize) flush();
  }
  void flush() {
    out_.write(text_.data(), static_cast<std::streamsize>(text_.size()));
    text_.clear();
  }

 private:
  static constexpr std::size_t kFlushSize = 1u << 20;
  void separator() {
    if (!first_) text_ += ',';
    first_ = false;
  }
  void append(const char* end) { text_.append(scratch_, static_cast<std::size_t>(end - scratch_)); }

  std::ostream& out_;
  std::string text_;
  char scratch_[32];
  bool first_ = true;
};

// The numbers of one CSV row, kept as they are until the worker formats them.
struct CsvRow {
  std::uint32_t sec, nsec, seq;
  const char* status;
  bool has_output, has_wave;
  GyroOutput output;  // meaningful when has_output
  double alpha;       // meaningful when has_wave
  double theta, amplitude, quadrature, phase;
};

// The CSV output of process: rows are collected in batches, and a background thread formats and
// writes each batch while the next is processed (formatting costs about as much as reading).
class CsvOutput {
 public:
  explicit CsvOutput(std::ostream& out) : text_(out) { rows_.reserve(kBatch); }
  CsvRow& next() {
    rows_.emplace_back();
    return rows_.back();
  }
  void endRow() {
    if (rows_.size() >= kBatch) submit();
  }
  /// Formats and writes the rest; rethrows what a batch threw.
  void finish() {
    submit();
    worker_.submit([this] { text_.flush(); });
    worker_.finish();
  }

 private:
  static constexpr std::size_t kBatch = 8192;
  void submit() {
    if (rows_.empty()) return;
    auto batch = std::make_shared<std::vector<CsvRow>>(std::move(rows_));
    rows_ = std::vector<CsvRow>();
    rows_.reserve(kBatch);
    worker_.submit([this, batch] {
      for (const CsvRow& r : *batch) format(r);
    });
  }
  void format(const CsvRow& r) {
    const bool o = r.has_output, w = r.has_wave;
    text_.stamp(r.sec, r.nsec);
    text_.integer(r.seq);
    text_.text(r.status);
    text_.number(r.output.dt, o);
    text_.number(r.output.dtheta, o);
    text_.number(r.output.dalpha, o);
    text_.number(r.output.dalpha_earth_fixed, o);
    text_.number(r.alpha, w);
    text_.number(r.output.rate, o);
    text_.number(r.output.theta_mid, o);
    text_.number(r.output.frequency, o);
    text_.number(r.output.scale_factor, o);
    text_.number(r.output.drift, o);
    if (o) {
      text_.integer(r.output.rejected_before);
      text_.integer(r.output.flags);
    } else {
      text_.text("");
      text_.text("");
    }
    text_.number(r.theta, w);
    text_.number(r.amplitude, w);
    text_.number(r.quadrature, w);
    text_.number(r.phase, w);
    text_.endRow();
  }

  CsvText text_;  // used by the worker only
  std::vector<CsvRow> rows_;
  bag_tools::SerialWorker worker_;  // last: stopped first
};

struct ProcessOptions {
  std::string bag, params, out, csv, frame_id = "gyro_link", compression = "lz4";
  bag_tools::GyroTopics topics;
  core::ProcessorConfig processor;
};

int runProcess(const ProcessOptions& o) {
  using namespace bag_tools;
  checkProcessorConfig(o.processor);
  checkOutputPaths({o.bag, o.params}, {o.out, o.csv});
  const auto params = std::make_shared<const core::GyroParameters>(core::loadParameterFile(o.params));
  const std::unique_ptr<rosbag::Bag> in = openBag(o.bag);
  const GyroTopics topics = findTopics(*in, o.topics, true, false);
  // Both outputs are temporaries until the whole bag has been processed.
  std::unique_ptr<OutputBag> out;
  if (!o.out.empty()) out = std::make_unique<OutputBag>(o.out, o.compression);
  std::unique_ptr<OutputText> csv_file;
  std::unique_ptr<CsvOutput> row;
  if (!o.csv.empty()) {
    csv_file = std::make_unique<OutputText>(o.csv);
    csv_file->stream()
        << "stamp,seq,status,dt,dtheta,dalpha,dalpha_earth_fixed,alpha,rate,theta_mid,frequency,scale_factor,drift,"
           "rejected_before,flags,theta,amplitude,quadrature,phase\n";
    row = std::make_unique<CsvOutput>(csv_file->stream());
  }
  core::GyroProcessor processor(o.processor, params);
  std::uint64_t outputs = 0;
  const std::string wave_topic = "/wave", output_topic = "/output";
  replayChannels(
      *in, topics.channels, processor,
      [&](const ChannelAmplitudes& msg, const core::ProcessorResult& r) {
        outputs += r.has_output ? 1 : 0;
        if (!out && !row) return;  // a dry run: the summary only
        const WaveState wave = toWaveMessage(msg, r.wave, o.frame_id);
        const GyroOutput output = toOutputMessage(wave.header, r);
        if (out && r.has_wave) out->write(wave_topic, msg.header.stamp, wave);
        if (out && r.has_output) out->write(output_topic, msg.header.stamp, output);
        if (row) {
          CsvRow& c = row->next();
          c.sec = msg.header.stamp.sec;
          c.nsec = msg.header.stamp.nsec;
          c.seq = msg.header.seq;
          c.status = verdictName(r);
          c.has_output = r.has_output;
          c.has_wave = r.has_wave;
          c.output = output;
          c.alpha = r.alpha;
          c.theta = wave.theta;
          c.amplitude = wave.amplitude;
          c.quadrature = wave.quadrature;
          c.phase = wave.phase;
          row->endRow();
        }
      },
      "process");
  if (csv_file) {
    row->finish();
    csv_file->commit();
  }
  if (out) out->commit();
  const core::ProcessorCounters& c = processor.counters();
  std::cerr << "process: " << c.received << " samples, " << outputs << " outputs, " << c.rejected() << " rejected, "
            << c.gaps << " gaps, " << c.resets << " resets\n";
  if (c.accepted == 0) {
    // Nothing usable: an output file of rejections only is not a successful run.
    std::cerr << "process: no sample accepted (" << c.non_finite << " non-finite, " << c.no_signal << " no signal, "
              << c.degenerate << " degenerate, " << c.amplitude_out_of_range << " amplitude out of range, "
              << c.zero_stamp << " zero stamp, " << c.duplicate << " duplicate, " << c.out_of_order << " out of order, "
              << c.jumps << " jumps)\n";
    return 1;
  }
  return 0;
}

}  // namespace

namespace bag_tools {

Command addProcessCommand(CLI::App& root) {
  auto o = std::make_shared<ProcessOptions>();
  CLI::App* cmd = root.add_subcommand("process", "the processor offline: /wave and /output into a bag, or a CSV");
  cmd->add_option("BAG", o->bag, "input bag with the gyro's channels")->required();
  cmd->add_option("--params", o->params, "parameter file (YAML) of the gyro, as the processor node's")->required();
  cmd->add_option("--out", o->out, "output bag: /wave and /output, recorded at the input's record time")
      ->check(tools::notEmpty());
  cmd->add_option("--csv", o->csv, "output CSV: one row per input sample with its verdict")->check(tools::notEmpty());
  cmd->add_option("--frame-id", o->frame_id, "frame_id of the written messages")
      ->check(tools::notEmpty())
      ->capture_default_str();
  addCompressionOption(*cmd, &o->compression);
  addTopicOptions(*cmd, &o->topics, false);
  addProcessorOptions(*cmd, &o->processor);
  cmd->footer(
      "Runs the processor on the bag's channels. Numbers in the CSV are in the shortest form that reads\n"
      "back exactly. With neither --out nor --csv, only the summary (a dry run).\n"
      "Outputs are written to temporaries and renamed over --out/--csv only when complete; an output\n"
      "that is the same file as an input or as the other output is refused.\n"
      "Exit 0 success, 1 when no sample was accepted, 2 bad usage or unreadable input, 3 an output\n"
      "could not be written (nothing left at its path, an existing file unchanged).");
  return [o] { return runProcess(*o); };
}

}  // namespace bag_tools

}  // namespace hrg_gyro
