// hrg_bag export: the raw channels and turntable states of a bag as the two CSV logs `hrg_bag
// import` reads, every number written so that it reads back to the same double (shortest
// round-trip form) and stamps as whole nanoseconds: export then import gives the same messages.
#include <charconv>
#include <iostream>

#include "../cli_checks.h"
#include "bag_tools.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/ros/conversions.h"
#include "read_messages.h"

namespace hrg_gyro {

namespace {

struct ExportOptions {
  std::string bag, channels_csv, turntable_csv;
  bag_tools::GyroTopics topics;
};

/// The shortest text that reads back to exactly `value` ("nan" for NaN).
void writeNumber(std::ostream& out, double value) {
  char text[32];
  out.write(text, std::to_chars(text, text + sizeof text, value).ptr - text);
}

int runExport(const ExportOptions& o) {
  using namespace bag_tools;
  checkOutputPaths({o.bag}, {o.channels_csv, o.turntable_csv});
  const std::unique_ptr<rosbag::Bag> bag = openBag(o.bag);
  const GyroTopics topics = findTopics(*bag, o.topics, true, !o.turntable_csv.empty());
  OutputText channels(o.channels_csv);
  std::unique_ptr<OutputText> turntable;
  if (!o.turntable_csv.empty()) turntable = std::make_unique<OutputText>(o.turntable_csv);
  channels.stream() << "# hrg_bag export of " << o.bag << " topic " << topics.channels << "\n"
                    << "stamp,ac,bc,as,bs,frequency,temperature,periods\n";
  if (turntable) {
    turntable->stream() << "# hrg_bag export of " << o.bag << " topic " << topics.turntable << "\n"
                        << "stamp,angle,rate\n";
  }
  std::vector<std::string> wanted{topics.channels};
  if (turntable) wanted.push_back(topics.turntable);
  rosbag::View view(*bag, rosbag::TopicQuery(wanted));
  Progress progress("export", view.size());
  std::uint64_t channel_count = 0, turntable_count = 0;
  const std::uint64_t n = readMessages(view, progress, [&](const rosbag::MessageInstance& m) {
    if (m.getTopic() == topics.channels) {
      const ChannelAmplitudes::ConstPtr c = m.instantiate<ChannelAmplitudes>();
      if (!c) return;
      std::ostream& out = channels.stream();
      out << toNanoseconds(c->header.stamp);
      for (double v : {c->c_in, c->c_quad, c->s_in, c->s_quad, c->frequency, c->temperature}) {
        out << ',';
        writeNumber(out, v);
      }
      out << ',' << c->periods << '\n';
      ++channel_count;
    } else {
      const TurntableState::ConstPtr t = m.instantiate<TurntableState>();
      if (!t) return;
      std::ostream& out = turntable->stream();
      out << toNanoseconds(t->header.stamp) << ',';
      writeNumber(out, t->angle);
      out << ',';
      writeNumber(out, t->rate);
      out << '\n';
      ++turntable_count;
    }
  });
  channels.commit();
  if (turntable) turntable->commit();
  progress.finish(n);
  std::cerr << "export: " << channel_count << " channel records to " << o.channels_csv;
  if (turntable) std::cerr << ", " << turntable_count << " turntable records to " << o.turntable_csv;
  std::cerr << "\n";
  return 0;
}

}  // namespace

namespace bag_tools {

Command addExportCommand(CLI::App& root) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* cmd = root.add_subcommand("export", "a bag's raw channels and turntable states as the CSV logs of import");
  cmd->add_option("BAG", o->bag, "input bag")->required();
  cmd->add_option("--channels-csv", o->channels_csv, "channel-amplitude log to write")
      ->required()
      ->check(tools::notEmpty());
  cmd->add_option("--turntable-csv", o->turntable_csv, "turntable log to write (needs a turntable topic)")
      ->check(tools::notEmpty());
  addTopicOptions(*cmd, &o->topics, true);
  cmd->footer(
      "Writes the columns `hrg_bag import` reads by default: stamp,ac,bc,as,bs,frequency,temperature,\n"
      "periods and stamp,angle,rate (rad, rad/s). Stamps are the header stamps in whole nanoseconds;\n"
      "numbers in the shortest form that reads back to the same double (NaN as nan), so importing the\n"
      "logs again gives the same channel and turntable messages. Each CSV replaces its path only when\n"
      "complete. Exit 0 success, 2 bad usage or unreadable bag, 3 a CSV could not be written.");
  return [o] { return runExport(*o); };
}

}  // namespace bag_tools
}  // namespace hrg_gyro
