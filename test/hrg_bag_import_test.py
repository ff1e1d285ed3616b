#!/usr/bin/env python3
"""hrg_bag import and export as a test engineer runs them: a simulated dual-rate session exported to
the two CSV logs and imported back calibrates to the same parameter file; bad records are refused
with file:line (exit 1, nothing written) or skipped and counted; bad options and inputs that are no
regular file exit 2 naming them; a full disk exits 3 leaving nothing; a 2-million-record log is
imported within the bag writer's documented memory bound. Needs no master."""
import math
import os
import shutil
import subprocess
import unittest

import rosbag
import rospy
import rostest

HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()


def hrg_bag(*args, timeout=600):
    p = subprocess.run([HRG_BAG] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def without(path, prefixes):
    """The lines of `path` but those starting (after indentation) with one of `prefixes`."""
    with open(path) as f:
        return [line for line in f if not line.strip().startswith(prefixes)]


def peak_rss_kb(*args):
    """Runs hrg_bag under /usr/bin/time; returns (exit code, stderr, peak resident set in KiB)."""
    report = os.path.join(rospy.get_param("~work_dir"), "hrg_bag_import", "time.txt")
    p = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", report, HRG_BAG] + list(args), stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, universal_newlines=True, timeout=600)
    with open(report) as f:
        return p.returncode, p.stderr, int(f.read().split()[-1])


CHANNELS_HEADER = "stamp,ac,bc,as,bs\n"


class HrgBagImport(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = os.path.join(rospy.get_param("~work_dir"), "hrg_bag_import")
        shutil.rmtree(cls.work, ignore_errors=True)
        os.makedirs(cls.work)
        cls.pkg = rospy.get_param("~package_dir")
        cls.params = os.path.join(cls.pkg, "config", "params_uncalibrated.yaml")

    def path(self, name):
        return os.path.join(self.work, name)

    def write(self, name, text):
        with open(self.path(name), "w") as f:
            f.write(text)
        return self.path(name)

    def test_help_names_the_formats_and_the_rate_method(self):
        code, out, _ = hrg_bag("import", "--help")
        self.assertEqual(code, 0)
        for fragment in ("usage: hrg_bag import", "--column", "--angle-unit", "--rate-unit", "--stamp-format",
                         "--delimiter", "--skip-bad-rows", "central difference", "ISO 8601", "a line over 1 MiB",
                         "from 2^32 s", "derived rate", "a FIFO"):
            self.assertIn(fragment, out)
        code, out, _ = hrg_bag("export", "--help")
        self.assertEqual(code, 0)
        self.assertIn("usage: hrg_bag export", out)

    def test_export_import_round_trip_calibrates_to_the_same_file(self):
        # The dual-rate scenario with one pair of plateaus instead of four (~490 s of session).
        with open(os.path.join(self.pkg, "config", "scenarios", "dual_rate.yaml")) as f:
            scenario = f.read()
        self.assertIn("repeat: 4", scenario)
        scenario_path = self.write("short_dual_rate.yaml", scenario.replace("repeat: 4", "repeat: 1"))
        original, imported = self.path("original.bag"), self.path("imported.bag")
        code, _, err = hrg_bag("simulate", "--scenario", scenario_path, "--out", original)
        self.assertEqual(code, 0, err)
        ch, tt = self.path("channels.csv"), self.path("turntable.csv")
        code, _, err = hrg_bag("export", original, "--channels-csv", ch, "--turntable-csv", tt)
        self.assertEqual(code, 0, err)
        code, _, err = hrg_bag("import", "--channels", ch, "--turntable", tt, "--out", imported)
        self.assertEqual(code, 0, err)
        # The same messages: exporting the imported bag gives the same logs but for the comment
        # line that names the bag.
        ch2, tt2 = self.path("channels2.csv"), self.path("turntable2.csv")
        code, _, err = hrg_bag("export", imported, "--channels-csv", ch2, "--turntable-csv", tt2)
        self.assertEqual(code, 0, err)
        self.assertEqual(without(ch, ("#",)), without(ch2, ("#",)))
        self.assertEqual(without(tt, ("#",)), without(tt2, ("#",)))
        with rosbag.Bag(original) as a, rosbag.Bag(imported) as b:
            for topic in ("/channels", "/turntable/state"):
                self.assertEqual(a.get_message_count(topic_filters=[topic]), b.get_message_count(topic_filters=[topic]))
        # Calibrated from either bag: the parameter files differ only in the calibration's source
        # line (the bag's path) and its time line (when the two runs fall in different seconds).
        outputs = []
        for bag in (original, imported):
            out = bag + ".params.yaml"
            code, stdout, err = hrg_bag("calibrate", bag, "--method", "dual_rate", "--params", self.params,
                                        "--out", out)
            self.assertEqual(code, 0, stdout + err)
            outputs.append(out)
        with open(outputs[0]) as a, open(outputs[1]) as b:
            differing = [(x, y) for x, y in zip(a, b) if x != y]
        self.assertIn(sorted({x.split(":")[0].strip() for x, _ in differing}), (["source"], ["source", "time"]),
                      differing)
        self.assertEqual(without(outputs[0], ("time:", "source:")), without(outputs[1], ("time:", "source:")))

    def test_units_stamps_and_mapped_columns(self):
        ch = self.write("mapped_channels.csv", "# bench 7\nt;Ac_V;Bc_V;As_V;Bs_V\n"
                        "2026-11-23T10:00:00.000000001Z;1;0;0;0\n2026-11-23T11:00:00.5+01:00;1;0;0;0\n")
        tt = self.write("mapped_turntable.csv", "time_s\tangle_deg\n1795428000.0\t0\n1795428000.5\t90\n")
        out = self.path("mapped.bag")
        code, _, err = hrg_bag("import", "--channels", ch, "--turntable", tt, "--out", out, "--angle-unit", "deg",
                               "--column", "stamp=#1", "ac=ac_v", "bc=Bc_V", "as=As_V", "bs=Bs_V",
                               "--column", "angle=angle_deg", "--quiet")
        self.assertEqual(code, 0, err)
        self.assertIn("central difference", err)
        with rosbag.Bag(out) as b:
            channels = [m for _, m, _ in b.read_messages(topics=["/channels"])]
            table = [m for _, m, _ in b.read_messages(topics=["/turntable/state"])]
        self.assertEqual([m.header.stamp.to_nsec() for m in channels], [1795428000000000001, 1795428000500000000])
        self.assertTrue(math.isnan(channels[0].frequency))
        self.assertEqual(len(table), 2)
        self.assertAlmostEqual(table[1].angle, math.pi / 2, places=15)
        self.assertAlmostEqual(table[0].rate, math.pi, places=12)  # 90 deg in 0.5 s

    def test_bad_records_are_refused_with_file_and_line_or_skipped_and_counted(self):
        ch = self.write("bad_channels.csv", CHANNELS_HEADER + "1.0,1,0,0,0\n2.0,1,0,0\n3.0,1.5abc,0,0,0\n"
                        "0.5,1,0,0,0\n4.0,1,0,0,0\n")
        out = self.path("bad.bag")
        code, _, err = hrg_bag("import", "--channels", ch, "--out", out)
        self.assertEqual(code, 1, err)
        self.assertIn(ch + ":3: wrong field count", err)
        self.assertNotIn("terminate called", err)
        self.assertFalse(os.path.exists(out))
        self.assertEqual([n for n in os.listdir(self.work) if n.startswith("bad.bag")], [])  # no temporary
        code, _, err = hrg_bag("import", "--channels", ch, "--out", out, "--skip-bad-rows")
        self.assertEqual(code, 0, err)
        self.assertIn("skipped records in %s: 3 (wrong field count 1, stamp not increasing 1, unreadable number 1)"
                      % ch, err)
        with rosbag.Bag(out) as b:
            self.assertEqual(b.get_message_count(), 2)
        semicolons = self.write("semicolons.csv", "stamp;ac;bc;as;bs\n1.0;1,5;0;0;0\n")
        code, _, err = hrg_bag("import", "--channels", semicolons, "--out", self.path("s.bag"))
        self.assertEqual(code, 1, err)
        self.assertIn(semicolons + ":2: unreadable number: ac: '1,5' is not a number", err)

    def test_bad_usage_exits_2_naming_the_option_or_column(self):
        ch = self.write("good_channels.csv", CHANNELS_HEADER + "1.0,1,0,0,0\n")
        out = self.path("usage.bag")
        cases = [
            (["--channels", self.path("missing.csv"), "--out", out], "--channels"),
            (["--channels", ch, "--out", out, "--column", "ac"], "--column expects KEY=COLUMN"),
            (["--channels", ch, "--out", out, "--column", "speed=x"], "unknown key 'speed'"),
            (["--channels", ch, "--out", out, "--column", "ac=Ac_V"], "no column 'Ac_V' for ac"),
            (["--channels", ch, "--out", out, "--angle-unit", "grad"], "--angle-unit"),
            (["--channels", ch, "--out", out, "--delimiter", "pipe"], "--delimiter"),
            (["--channels", ch, "--out", out, "--no-header"], "--column stamp=#N"),
            (["--channels", ch, "--out", ch], "refused"),
            (["--channels", ch, "--turntable", self.write("no_rate.csv", "stamp,speed\n1,2\n"), "--out", out],
             "needs an angle or a rate column"),
            (["--channels", ch, "--out", out, "--channels-topic", "channels"], "--channels-topic: must be a global"),
            (["--channels", ch, "--out", out, "--channels-topic", "/gyro channels"], "is not a ROS topic name"),
            (["--channels", ch, "--out", out, "--channels-topic", "/gyro/\nchannels"], "is not a ROS topic name"),
            (["--channels", ch, "--out", out, "--channels-topic", "/gyro-1"], "is not a ROS topic name"),
            (["--channels", ch, "--out", out, "--channels-topic", "/gyro//channels"], "'//'"),
            (["--channels", ch, "--out", out, "--turntable-topic", "/turntable/"], "--turntable-topic: must not"),
            (["--channels", ch, "--out", out, "--turntable-topic", "~state"], "--turntable-topic: must be a global"),
            (["--channels", ch, "--out", out, "--channels-topic", "/"], "--channels-topic: must not"),
            (["--channels", ch, "--turntable", self.write("rate.csv", "stamp,rate\n1.0,0.1\n"), "--out", out,
              "--channels-topic", "/gyro", "--turntable-topic", "/gyro"],
             "--channels-topic and --turntable-topic are both /gyro"),
            (["--channels", ch, "--out", out, "--frame-id", "gyro\nlink"], "--frame-id: must not hold blanks"),
            (["--channels", ch, "--out", out, "--frame-id", "gyro link"], "--frame-id: must not hold blanks"),
            (["--channels", ch, "--out", out, "--frame-id", "/gyro_link"], "--frame-id: must not start with '/'"),
        ]
        for args, fragment in cases:
            code, _, err = hrg_bag("import", *args)
            self.assertEqual(code, 2, "%s -> %d\n%s" % (args, code, err))
            self.assertIn(fragment, err, args)
            self.assertNotIn("terminate called", err)
            self.assertFalse(os.path.exists(out), args)
        # The two topics may be equal when only one is written; names and frames of other forms are taken.
        for extra in (["--channels-topic", "/turntable/state"], ["--channels-topic", "/bench_7/gyro_2/channels"],
                      ["--frame-id", "bench.gyro-2_link"]):
            code, _, err = hrg_bag("import", "--channels", ch, "--out", out, "--quiet", *extra)
            self.assertEqual(code, 0, "%s\n%s" % (extra, err))
            os.remove(out)

    def test_a_long_field_is_quoted_as_an_excerpt(self):
        # A 500 kB field (within the line limit) is named by its first 64 bytes and its size.
        field = "x" + "9" * 500000
        ch = self.write("long_field.csv", CHANNELS_HEADER + "1.0,%s,0,0,0\n" % field)
        code, _, err = hrg_bag("import", "--channels", ch, "--out", self.path("long_field.bag"))
        self.assertEqual(code, 1, err[:500])
        self.assertIn(ch + ":2: unreadable number: ac: 'x" + "9" * 63 + "... (500001 bytes)' is not a number", err)
        self.assertLess(len(err), 1000, err[:500])
        header = self.write("long_header.csv", "stamp," + "h" * 500000 + ",bc,as,bs\n1.0,1,0,0,0\n")
        code, _, err = hrg_bag("import", "--channels", header, "--out", self.path("long_field.bag"))
        self.assertEqual(code, 2, err[:500])
        self.assertIn("no column 'ac' for ac in the header ('stamp', '" + "h" * 64 + "... (500000 bytes)', 'bc'", err)
        self.assertLess(len(err), 1000, err[:500])

    def test_a_stamp_a_bag_cannot_hold_is_a_bad_record(self):
        # ros::Time holds [1 ns, 2^32 s - 1 ns]: a stamp outside is the log's fault (exit 1 with
        # FILE:LINE), never a failure to write the bag (exit 3).
        tt = self.write("range_turntable.csv", "stamp,rate\n1.0,0.1\n4294967296.0,0.1\n")
        for stamp, line in (("0", 3), ("4294967296.0", 3), ("99999999999999999999", 3)):
            ch = self.write("range_channels.csv", CHANNELS_HEADER + "1.0,1,0,0,0\n%s,1,0,0,0\n" % stamp)
            code, _, err = hrg_bag("import", "--channels", ch, "--out", self.path("range.bag"))
            self.assertEqual(code, 1, err)
            self.assertIn("%s:%d: stamp out of range: stamp " % (ch, line), err)
        code, _, err = hrg_bag("import", "--channels", ch, "--turntable", tt, "--out", self.path("range.bag"),
                               "--skip-bad-rows", "--quiet")
        self.assertEqual(code, 0, err)
        self.assertIn("skipped records in %s: 1 (stamp out of range 1)" % ch, err)
        self.assertIn("skipped records in %s: 1 (stamp out of range 1)" % tt, err)
        ch = self.write("range_ends.csv", CHANNELS_HEADER + "0.000000001,1,0,0,0\n4294967295.999999999,1,0,0,0\n")
        code, _, err = hrg_bag("import", "--channels", ch, "--out", self.path("range.bag"), "--quiet")
        self.assertEqual(code, 0, err)
        with rosbag.Bag(self.path("range.bag")) as b:
            self.assertEqual([m.header.stamp.to_nsec() for _, m, _ in b.read_messages()],
                             [1, 4294967295999999999])

    def test_an_infinite_derived_rate_is_a_bad_record(self):
        # Finite angles whose difference overflows: the rate of the record between them is refused
        # with its own line (not the line read ahead), or skipped leaving the other rates as they were.
        ch = self.write("overflow_channels.csv", CHANNELS_HEADER + "".join("%d.0,1,0,0,0\n" % i for i in range(1, 6)))
        tt = self.write("overflow_turntable.csv", "stamp,angle\n1.0,0\n2.0,1e308\n3.0,2\n4.0,-1e308\n5.0,4\n")
        out = self.path("overflow.bag")
        code, _, err = hrg_bag("import", "--channels", ch, "--turntable", tt, "--out", out)
        self.assertEqual(code, 1, err)
        self.assertIn(tt + ":4: NaN or infinity not allowed: rate derived from the angle is -inf", err)
        self.assertFalse(os.path.exists(out))
        code, _, err = hrg_bag("import", "--channels", ch, "--turntable", tt, "--out", out, "--skip-bad-rows",
                               "--quiet")
        self.assertEqual(code, 0, err)
        self.assertIn("skipped records in %s: 1 (NaN or infinity not allowed 1)" % tt, err)
        with rosbag.Bag(out) as b:
            table = [(m.header.stamp.to_sec(), m.rate) for _, m, _ in b.read_messages(topics=["/turntable/state"])]
        self.assertEqual([t for t, _ in table], [1.0, 2.0, 4.0, 5.0])
        self.assertEqual(table[2][1], 1.0)  # (4 - 2) / 2: the skipped record's good angle is still a neighbour
        self.assertTrue(all(math.isfinite(rate) for _, rate in table), table)

    def test_a_line_longer_than_the_limit_is_a_bad_record(self):
        # The reader never holds more than 1 MiB of a line: a longer record is a bad record, a file
        # without line ends (no header row within the limit) is no log.
        long_field = "4" * (2 << 20)
        ch = self.write("long_line.csv", CHANNELS_HEADER + "1.0,1,0,0,0\n2.0,1,0,0," + long_field + "\n3.0,1,0,0,0\n")
        out = self.path("long_line.bag")
        code, _, err = hrg_bag("import", "--channels", ch, "--out", out)
        self.assertEqual(code, 1, err)
        self.assertIn(ch + ":3: line too long: more than 1048576 bytes (1 MiB), the limit of a line", err)
        self.assertLess(len(err), 4096, "the line is not echoed")
        self.assertFalse(os.path.exists(out))
        code, _, err = hrg_bag("import", "--channels", ch, "--out", out, "--skip-bad-rows", "--quiet")
        self.assertEqual(code, 0, err)
        self.assertIn("skipped records in %s: 1 (line too long 1)" % ch, err)
        with rosbag.Bag(out) as b:
            self.assertEqual([m.header.stamp.to_sec() for _, m, _ in b.read_messages()], [1.0, 3.0])
        binary = self.write("no_line_ends.dat", "x" * (3 << 20))
        code, _, err = hrg_bag("import", "--channels", binary, "--out", self.path("binary.bag"))
        self.assertEqual(code, 2, err)
        self.assertIn(binary + ":1: line too long", err)
        self.assertLess(len(err), 4096)

    def test_fifos_devices_and_directories_are_refused_without_blocking(self):
        # A FIFO without a writer would block an ordinary open forever; the log is checked before it
        # is opened, so the import ends at once (the short timeout turns a regression into a failure).
        ch = self.write("fifo_case_channels.csv", CHANNELS_HEADER + "1.0,1,0,0,0\n")
        fifo, directory = self.path("log_fifo"), self.path("log_directory")
        os.mkfifo(fifo)
        os.makedirs(directory)
        out = self.path("fifo_case.bag")
        for bad, why in ((fifo, "is a FIFO"), ("/dev/null", "is a character device"), (directory, "is a directory")):
            for args, option in ((["--channels", bad], "--channels"), (["--channels", ch, "--turntable", bad],
                                                                       "--turntable")):
                code, _, err = hrg_bag("import", *(args + ["--out", out]), timeout=20)
                self.assertEqual(code, 2, "%s -> exit %d\n%s" % (args, code, err))
                self.assertIn(option + ": '" + bad + "' " + why, err)
                self.assertFalse(os.path.exists(out))

    def test_a_full_disk_fails_with_exit_3_and_leaves_nothing(self):
        ch = self.path("disk_channels.csv")
        with open(ch, "w") as f:
            f.write(CHANNELS_HEADER)
            f.writelines("%d,0.9,0.1,-0.2,0.01\n" % (1000000000 + i * 5000000) for i in range(20000))
        disk = self.path("full_disk")
        os.makedirs(disk)
        mount = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", disk], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, universal_newlines=True)
        if mount.returncode != 0:
            self.skipTest("cannot mount a 64 KiB tmpfs to fill (needs root): " + mount.stdout.strip())
        try:
            out = os.path.join(disk, "full.bag")
            code, _, err = hrg_bag("import", "--channels", ch, "--out", out, "--quiet")
            self.assertEqual(code, 3, err)
            self.assertIn("No space left on device", err)
            self.assertEqual(os.listdir(disk), [])
        finally:
            subprocess.run(["umount", disk])

    # The bag writer's worst case (BagFileWriter::kMaxChunksAlive, docs/importing_logs.md): three 4 MiB
    # chunks (filling, waiting, being written) with their indexes, about 14.7 MiB for these messages,
    # the compression buffer and LZ4's own 5.2 MiB, the 4 MiB write stage, about 24 MiB together; 2 MiB
    # more for the allocator. Holding the 2 M records instead would take more than 100 MiB.
    WRITER_WORST_CASE_KIB = 26 * 1024

    def test_a_large_log_is_streamed_in_flat_memory(self):
        # How many chunks are alive depends on how far the writer's thread falls behind, i.e. on the
        # machine's load, so the peak is compared with an import that never fills a chunk (1000
        # records, the libraries and buffers alone) plus the writer's worst case, not with a 100 000-
        # record import. Measured on the 2-core machine (peak RSS, 3 runs each, with and without two
        # busy loops, other work running): 1000 records 17.8-18.3 MB either way; 2 M records (8 M
        # alike) 41.3-42.0 MB either way. Before the bound was made explicit (a chunk taken before the
        # full one was queued, two waiting): 36.9 MB on an idle machine, 50.5-50.9 MB loaded, which
        # failed the old comparison with 100 000 records (35.0-39.6 MB) + 8 MiB.
        row = "0.9374203025250911,-0.2941238247148178,0.1959980714562781,-0.040112536931700485,5000,21.5,25\n"
        peaks = {}
        for n in (1000, 2000000):
            ch = self.path("large_%d.csv" % n)
            with open(ch, "w") as f:
                f.write("stamp,ac,bc,as,bs,frequency,temperature,periods\n")
                f.writelines("%d,%s" % (1000000000 + i * 5000000, row) for i in range(n))
            out = self.path("large_%d.bag" % n)
            code, err, peaks[n] = peak_rss_kb("import", "--channels", ch, "--out", out, "--quiet")
            self.assertEqual(code, 0, err)
            self.assertIn("%d channel records" % n, err)
            os.remove(ch)
            os.remove(out)
        print("peak RSS: 1000 records %d KiB, 2M records %d KiB" % (peaks[1000], peaks[2000000]))
        self.assertLess(peaks[2000000], peaks[1000] + self.WRITER_WORST_CASE_KIB, peaks)


if __name__ == "__main__":
    rospy.init_node("hrg_bag_import_test")
    rostest.rosrun("hrg_gyro", "hrg_bag_import", HrgBagImport)
