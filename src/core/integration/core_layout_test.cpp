// The core's layout is its design: every file sits in one concept folder, and the folders depend on
// each other one way only, in the order below (a folder's library code includes only its own folder
// and those before it; tests may use any folder, the simulator above all, to make their data).
// Each folder says in its README.md what it holds and what it may include, and every unit test in a
// folder is named after a module of that folder (foo.cpp / foo.h -> foo_test.cpp). A folder may gather
// the files of one part of its concept in a sub-folder (calibration/triad: the triad's calibration),
// which has the folder's place in the order and a README.md of its own; the folder's other files do
// not include it (the sub-folder builds on them, not they on it).
#include <dirent.h>
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

const std::vector<std::string> kFolders = {"common",     "model",     "resonator",   "signal",     "estimation",
                                           "processing", "alignment", "calibration", "simulation", "evaluation"};
// The sub-folders, as "folder/sub": no other directory may stand inside a concept folder.
const std::set<std::string> kSubFolders = {"calibration/triad"};

std::vector<std::string> entries(const std::string& dir, bool directories) {
  std::vector<std::string> out;
  DIR* d = opendir(dir.c_str());
  if (!d) return out;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name == "." || name == "..") continue;
    if ((e->d_type == DT_DIR) == directories) out.push_back(name);
  }
  closedir(d);
  return out;
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class CoreLayoutTest : public ::testing::Test {
 protected:
  const std::string root_ = HRG_GYRO_SOURCE_DIR;
  const std::string include_ = root_ + "/include/hrg_gyro/core";
  const std::string src_ = root_ + "/src/core";
};

TEST_F(CoreLayoutTest, EveryFileSitsInAConceptFolder) {
  EXPECT_TRUE(entries(include_, false).empty()) << "headers directly in include/hrg_gyro/core";
  EXPECT_TRUE(entries(src_, false).empty()) << "files directly in src/core";
  std::set<std::string> allowed(kFolders.begin(), kFolders.end());
  for (const std::string& d : entries(include_, true)) EXPECT_TRUE(allowed.count(d)) << "include/hrg_gyro/core/" << d;
  allowed.insert({"integration", "testing"});  // cross-module tests and their helpers
  for (const std::string& d : entries(src_, true)) EXPECT_TRUE(allowed.count(d)) << "src/core/" << d;
  for (const std::string& f : kFolders) {
    EXPECT_FALSE(read(src_ + "/" + f + "/README.md").empty()) << "src/core/" << f << "/README.md";
    for (const std::string& base : {include_, src_}) {
      for (const std::string& sub : entries(base + "/" + f, true)) {
        EXPECT_TRUE(kSubFolders.count(f + "/" + sub)) << base << "/" << f << "/" << sub << " is no known sub-folder";
        EXPECT_TRUE(entries(base + "/" + f + "/" + sub, true).empty())
            << base << "/" << f << "/" << sub << " holds a directory";
      }
    }
  }
  for (const std::string& sub : kSubFolders) {
    EXPECT_FALSE(read(src_ + "/" + sub + "/README.md").empty()) << "src/core/" << sub << "/README.md";
  }
}

/// The concept folders and their sub-folders ("calibration", "calibration/triad", ...), each with
/// the rank of its folder in the order.
std::vector<std::pair<std::string, int>> rankedFolders() {
  std::vector<std::pair<std::string, int>> out;
  for (std::size_t i = 0; i < kFolders.size(); ++i) {
    out.emplace_back(kFolders[i], static_cast<int>(i));
    for (const std::string& sub : kSubFolders) {
      if (sub.compare(0, kFolders[i].size() + 1, kFolders[i] + "/") == 0) out.emplace_back(sub, static_cast<int>(i));
    }
  }
  return out;
}

TEST_F(CoreLayoutTest, FoldersDependOneWay) {
  std::map<std::string, int> rank;
  for (const auto& [folder, r] : rankedFolders()) rank[folder] = r;
  const std::regex include(R"(#\s*include\s*"hrg_gyro/core/([a-z_]+(/[a-z_]+)?)/([a-z_0-9]+\.h)\")");
  int checked = 0;
  for (const auto& [folder, folder_rank] : rankedFolders()) {
    std::vector<std::string> files;
    for (const std::string& h : entries(include_ + "/" + folder, false))
      files.push_back(include_ + "/" + folder + "/" + h);
    for (const std::string& c : entries(src_ + "/" + folder, false)) {
      if (endsWith(c, ".cpp") && !endsWith(c, "_test.cpp")) files.push_back(src_ + "/" + folder + "/" + c);
    }
    for (const std::string& path : files) {
      const std::string text = read(path);
      for (std::sregex_iterator it(text.begin(), text.end(), include), end; it != end; ++it) {
        const std::string used = (*it)[1];
        ASSERT_TRUE(rank.count(used)) << path << " includes an unknown folder " << used;
        EXPECT_LE(rank[used], folder_rank) << path << " (" << folder << ") includes " << used << "/" << (*it)[3]
                                           << ": folders may only use those before them";
        // A sub-folder is used by what comes after its folder, not by its folder's own files.
        EXPECT_NE(used.compare(0, folder.size() + 1, folder + "/"), 0)
            << path << " (" << folder << ") includes its sub-folder's " << used << "/" << (*it)[3];
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 60);
}

TEST_F(CoreLayoutTest, UnitTestsAreNamedAfterTheirModule) {
  for (const auto& folder : rankedFolders()) {
    const std::string& f = folder.first;
    std::set<std::string> modules;
    for (const std::string& h : entries(include_ + "/" + f, false)) modules.insert(h.substr(0, h.rfind('.')));
    for (const std::string& c : entries(src_ + "/" + f, false)) {
      if (!endsWith(c, "_test.cpp")) continue;
      const std::string module = c.substr(0, c.size() - std::string("_test.cpp").size());
      EXPECT_TRUE(modules.count(module)) << "src/core/" << f << "/" << c << " names no module of " << f;
    }
  }
}

// A module is a header or a library source (tests excluded) by its name without extension, in the folder
// or in a sub-folder of it.
std::set<std::string> modulesIn(const std::string& dir) {
  std::set<std::string> out;
  for (const std::string& f : entries(dir, false)) {
    if (endsWith(f, "_test.cpp") || !(endsWith(f, ".cpp") || endsWith(f, ".h"))) continue;
    out.insert(f.substr(0, f.rfind('.')));
  }
  for (const std::string& d : entries(dir, true)) {
    for (const std::string& m : modulesIn(dir + "/" + d)) out.insert(m);
  }
  return out;
}

bool names(const std::string& text, const std::string& module) {
  return std::regex_search(text, std::regex("(^|[^a-z0-9_])" + module + "([^a-z0-9_]|$)"));
}

// The maps are true: a newcomer who reads a folder's README, or docs/layout.md, learns of every file in it.
TEST_F(CoreLayoutTest, EveryModuleIsNamedInItsFoldersReadmeAndInTheLayout) {
  const std::string layout = read(root_ + "/docs/layout.md");
  ASSERT_FALSE(layout.empty()) << "docs/layout.md";
  int checked = 0;
  for (const std::string& folder : kFolders) {
    std::set<std::string> modules = modulesIn(include_ + "/" + folder);
    for (const std::string& m : modulesIn(src_ + "/" + folder)) modules.insert(m);
    std::string readme = read(src_ + "/" + folder + "/README.md");
    for (const std::string& d : entries(src_ + "/" + folder, true))
      readme += read(src_ + "/" + folder + "/" + d + "/README.md");
    for (const std::string& m : modules) {
      EXPECT_TRUE(names(readme, m)) << m << " (core/" << folder << ") is not named in src/core/" << folder
                                    << "/README.md";
      EXPECT_TRUE(names(layout, m)) << m << " (core/" << folder << ") is not named in docs/layout.md";
      ++checked;
    }
  }
  EXPECT_GT(checked, 60);
}

// Beyond the core: the ROS layer, the offline tools and the core's test helpers are in docs/layout.md too.
TEST_F(CoreLayoutTest, EveryWrapperToolAndTestHelperIsNamedInTheLayout) {
  const std::string layout = read(root_ + "/docs/layout.md");
  int checked = 0;
  for (const std::string dir : {"/include/hrg_gyro/ros", "/src/ros", "/src/tools", "/src/core/testing"}) {
    for (const std::string& m : modulesIn(root_ + dir)) {
      EXPECT_TRUE(names(layout, m)) << m << " (" << dir.substr(1) << ") is not named in docs/layout.md";
      ++checked;
    }
  }
  EXPECT_GT(checked, 40);
}

}  // namespace
