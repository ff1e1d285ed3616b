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

// One CSV row. Numbers in the shortest form that reads back to the same double (std::to_chars),
// several times faster than printf's %.17g and just as exact.
class CsvRow {
 public:
  void clear() { line_.clear(); }
  void number(double v, bool present = true) {
    separator();
    if (!present) return;
    char buf[32];
    line_.append(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
  }
  void integer(std::uint64_t v) {
    separator();
    char buf[24];
    line_.append(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
  }
  void stamp(std::uint32_t sec, std::uint32_t nsec) {
    separator();
    char buf[24];
    std::snprintf(buf, sizeof buf, "%u.%09u", sec, nsec);
    line_ += buf;
  }
  void text(const char* t) {
    separator();
    line_ += t;
  }
  void end() {
    line_ += '\n';
    first_ = true;
  }
  const std::string& line() const { return line_; }

 private:
  void separator() {
    if (!first_) line_ += ',';
    first_ = false;
  }
  std::string line_;
  bool first_ = true;
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
  if (!o.csv.empty()) {
    csv_file = std::make_unique<OutputText>(o.csv);
    csv_file->stream()
        << "stamp,seq,status,dt,dtheta,dalpha,dalpha_earth_fixed,alpha,rate,theta_mid,frequency,scale_factor,drift,"
           "rejected_before,flags,theta,amplitude,quadrature,phase\n";
  }
  core::GyroProcessor processor(o.processor, params);
  std::uint64_t outputs = 0;
  CsvRow row;
  std::string csv_buffer;
  replayChannels(
      *in, topics.channels, processor,
      [&](const ChannelAmplitudes& msg, const core::ProcessorResult& r) {
        const WaveState wave = toWaveMessage(msg, r.wave, o.frame_id);
        const GyroOutput output = toOutputMessage(wave.header, r);
        if (out && r.has_wave) out->write("/wave", msg.header.stamp, wave);
        if (out && r.has_output) out->write("/output", msg.header.stamp, output);
        outputs += r.has_output ? 1 : 0;
        if (csv_file) {
          row.clear();
          row.stamp(msg.header.stamp.sec, msg.header.stamp.nsec);
          row.integer(msg.header.seq);
          row.text(verdictName(r));
          const bool o = r.has_output, w = r.has_wave;
          row.number(output.dt, o);
          row.number(output.dtheta, o);
          row.number(output.dalpha, o);
          row.number(output.dalpha_earth_fixed, o);
          row.number(r.alpha, w);
          row.number(output.rate, o);
          row.number(output.theta_mid, o);
          row.number(output.frequency, o);
          row.number(output.scale_factor, o);
          row.number(output.drift, o);
          if (o) {
            row.integer(output.rejected_before);
            row.integer(output.flags);
          } else {
            row.text("");
            row.text("");
          }
          row.number(wave.theta, w);
          row.number(wave.amplitude, w);
          row.number(wave.quadrature, w);
          row.number(wave.phase, w);
          row.end();
          csv_buffer += row.line();
          if (csv_buffer.size() > (1u << 20)) {
            csv_file->stream() << csv_buffer;
            csv_buffer.clear();
          }
        }
      },
      "process");
  if (csv_file) {
    csv_file->stream() << csv_buffer;
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
