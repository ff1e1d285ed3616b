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

// The maps name only what is there: a file table's entry (a folder README's `## Files` table, the
// core table of docs/layout.md) is a module of its folder, and a file a README, the layout or a core
// header's comment names by its name (foo.h, bar.cpp, baz.md) exists in the repository.
std::vector<std::string> backticked(const std::string& cell) {
  std::vector<std::string> out;
  const std::regex name("`([a-z_0-9]+)`");
  for (std::sregex_iterator it(cell.begin(), cell.end(), name), end; it != end; ++it) out.push_back((*it)[1]);
  return out;
}

// A Markdown table's entries in one column, the header's and the rule's rows aside; with column > 0
// each row's first cell comes first, marked by a leading '|'.
std::vector<std::string> tableEntries(const std::string& text, int column) {
  std::vector<std::string> out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.compare(0, 2, "| ") != 0 || line.compare(0, 5, "| ---") == 0) continue;
    std::vector<std::string> cells;
    std::istringstream row(line.substr(1));
    for (std::string cell; std::getline(row, cell, '|');) cells.push_back(cell);
    if (static_cast<int>(cells.size()) <= column) continue;
    if (column > 0) out.push_back("|" + cells[0]);  // the row's folder, then its entries
    for (const std::string& e : backticked(cells[static_cast<std::size_t>(column)])) out.push_back(e);
  }
  return out;
}

// Every file name of the repository, the build and the VCS's own trees excluded.
void collectFileNames(const std::string& dir, std::set<std::string>* names) {
  for (const std::string& f : entries(dir, false)) names->insert(f);
  for (const std::string& d : entries(dir, true)) {
    if (d[0] == '.' || d == "build" || d == "devel" || d == "install") continue;
    collectFileNames(dir + "/" + d, names);
  }
}

// The file names a text names (foo.h, bar_baz.cpp, README.md), placeholders (foo, bar) aside; in
// comments_only mode just those in // comments, so an #include is not taken for a claim.
std::set<std::string> namedFiles(const std::string& text, bool comments_only) {
  std::set<std::string> out;
  const std::regex file(R"((^|[^A-Za-z0-9_.-])([a-z][a-z_0-9]*\.(h|cpp|md|py))\b)");
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (comments_only) {
      const std::size_t c = line.find("//");
      if (c == std::string::npos) continue;
      line = line.substr(c);
    }
    for (std::sregex_iterator it(line.begin(), line.end(), file), end; it != end; ++it) {
      const std::string n = (*it)[2];
      if (n.compare(0, 3, "foo") != 0 && n.compare(0, 3, "bar") != 0) out.insert(n);
    }
  }
  return out;
}

TEST_F(CoreLayoutTest, TablesAndTextsNameOnlyFilesThatExist) {
  int checked = 0;
  for (const auto& [folder, rank] : rankedFolders()) {
    (void)rank;
    std::set<std::string> modules = modulesIn(include_ + "/" + folder);
    for (const std::string& m : modulesIn(src_ + "/" + folder)) modules.insert(m);
    const std::string readme = read(src_ + "/" + folder + "/README.md");
    const std::size_t files = readme.find("## Files");
    ASSERT_NE(files, std::string::npos) << "src/core/" << folder << "/README.md has no ## Files table";
    for (const std::string& m : tableEntries(readme.substr(files), 0)) {
      EXPECT_TRUE(modules.count(m)) << "src/core/" << folder << "/README.md lists " << m << ", no file of " << folder;
      ++checked;
    }
  }
  // docs/layout.md: a core row (folder | files | concept) names files of its folder; the other tables'
  // first column (the ROS layer, the tools, the test helpers) names files somewhere in src/ or include/.
  std::map<std::string, int> rank;
  for (const auto& [folder, r] : rankedFolders()) rank[folder] = r;
  std::set<std::string> anywhere = modulesIn(root_ + "/src");
  for (const std::string& m : modulesIn(root_ + "/include")) anywhere.insert(m);
  std::string folder;
  for (const std::string& e : tableEntries(read(root_ + "/docs/layout.md"), 1)) {
    if (e[0] == '|') {
      std::istringstream cell(e.substr(1));
      folder.clear();
      cell >> folder;
      if (!rank.count(folder)) {
        for (const std::string& m : backticked(e)) {
          EXPECT_TRUE(anywhere.count(m)) << "docs/layout.md lists " << m << ", no file of src/ or include/";
          ++checked;
        }
      }
      continue;
    }
    if (!rank.count(folder)) continue;
    std::set<std::string> modules = modulesIn(include_ + "/" + folder);
    for (const std::string& m : modulesIn(src_ + "/" + folder)) modules.insert(m);
    EXPECT_TRUE(modules.count(e)) << "docs/layout.md lists " << e << " under " << folder << ", no file of it";
    ++checked;
  }
  EXPECT_GT(checked, 120);

  std::set<std::string> existing;
  collectFileNames(root_, &existing);
  std::vector<std::pair<std::string, bool>> texts = {{"/docs/layout.md", false}, {"/README.md", false}};
  for (const auto& [folder, rank] : rankedFolders()) {
    (void)rank;
    texts.emplace_back("/src/core/" + folder + "/README.md", false);
    for (const std::string& h : entries(include_ + "/" + folder, false))
      texts.emplace_back("/include/hrg_gyro/core/" + folder + "/" + h, true);
  }
  int named = 0;
  for (const auto& [path, comments_only] : texts) {
    for (const std::string& n : namedFiles(read(root_ + path), comments_only)) {
      EXPECT_TRUE(existing.count(n)) << path.substr(1) << " names " << n << ", which does not exist";
      ++named;
    }
  }
  EXPECT_GT(named, 50);
}

// The check itself: it sees a file table's entry that names no file, and a comment's file that is gone.
TEST(CoreLayoutCheck, SeesANamedFileThatIsMissing) {
  EXPECT_EQ(tableEntries("| file | concept |\n| --- | --- |\n| `a`, `b_c` | x |\n", 0),
            (std::vector<std::string>{"a", "b_c"}));
  EXPECT_EQ(namedFiles("#include \"x/gone.h\"\n// see gone_too.h and foo.cpp\n", true),
            (std::set<std::string>{"gone_too.h"}));
  EXPECT_EQ(namedFiles("the table (`kept.cpp`, docs/x_y.md)\n", false), (std::set<std::string>{"kept.cpp", "x_y.md"}));
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
