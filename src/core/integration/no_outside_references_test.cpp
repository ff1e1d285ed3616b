// The repository must explain itself: no file may cite documents that are not in it (the physics
// notes and the requirements the project started from). Their content lives in docs/ in the
// project's own words; a citation of the old files would send a reader to something they cannot
// open. The test walks the whole checkout (not the workspace, git's data or run outputs) and lists
// every offending file:line.
#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cctype>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

// Directories at the top of the checkout that are not the repository's content.
const std::set<std::string> kSkippedTopDirectories = {".git", ".ws", "run_output", "bench_output"};
// Generated or binary files that cannot hold a citation written by a person.
const std::vector<std::string> kSkippedSuffixes = {".png", ".bag", ".pyc"};

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Regular files under dir, not following symbolic links (the workspace links back to the checkout).
void listFiles(const std::string& dir, bool top, std::vector<std::string>* out) {
  DIR* d = opendir(dir.c_str());
  if (!d) return;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name == "." || name == ".." || name == "__pycache__") continue;
    if (top && kSkippedTopDirectories.count(name)) continue;
    const std::string path = dir + "/" + name;
    struct stat st;
    if (lstat(path.c_str(), &st) != 0) continue;
    if (S_ISDIR(st.st_mode)) {
      listFiles(path, false, out);
    } else if (S_ISREG(st.st_mode)) {
      bool skipped = false;
      for (const auto& suffix : kSkippedSuffixes) skipped = skipped || endsWith(name, suffix);
      if (!skipped) out->push_back(path);
    }
  }
  closedir(d);
}

bool isWordCharacter(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// The citations looked for. The names are assembled at run time so that this file does not cite them.
std::string outsideReference(const std::string& line) {
  const std::string math_notes = std::string("MATH") + ".md";
  const std::string shared_folder = std::string("..") + "/shared";
  const std::string spec = std::string("SP") + "EC";
  if (line.find(math_notes) != std::string::npos) return math_notes;
  if (line.find(shared_folder) != std::string::npos) return shared_folder;
  // The requirements document's name, alone or followed by ".md" or a section; not inside a longer word.
  for (std::size_t at = line.find(spec); at != std::string::npos; at = line.find(spec, at + 1)) {
    const bool starts_word = at == 0 || !isWordCharacter(line[at - 1]);
    const std::size_t end = at + spec.size();
    const bool ends_word = end == line.size() || !isWordCharacter(line[end]);
    if (starts_word && ends_word) return spec;
  }
  return "";
}

TEST(Repository, CitesNoDocumentOutsideItself) {
  const std::string root = HRG_GYRO_SOURCE_DIR;
  std::vector<std::string> files;
  listFiles(root, true, &files);
  ASSERT_GT(files.size(), 100u) << "walked " << root;
  std::ostringstream offences;
  int count = 0;
  for (const auto& path : files) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      const std::string cited = outsideReference(line);
      if (cited.empty()) continue;
      ++count;
      offences << "\n  " << path.substr(root.size() + 1) << ":" << n << ": cites " << cited << ": "
               << line.substr(0, 160);
    }
  }
  EXPECT_EQ(count, 0) << "say it in the project's own words (docs/) instead:" << offences.str();
}

// The check itself: each form of citation is found, and ordinary words that contain the letters
// are not.
TEST(Repository, OutsideReferenceDetectorFindsEachForm) {
  EXPECT_FALSE(outsideReference(std::string("// (") + "MATH" + ".md section 3)").empty());
  EXPECT_FALSE(outsideReference(std::string("see ../") + "shared/notes.txt").empty());
  EXPECT_FALSE(outsideReference(std::string("## Targets (") + "SP" + "EC section 8)").empty());
  EXPECT_FALSE(outsideReference(std::string("SP") + "EC.md").empty());
  EXPECT_TRUE(outsideReference("// (docs/math.md, 'Correction matrix')").empty());
  EXPECT_TRUE(outsideReference(std::string("CMAKE_") + "SP" + "EC_FILE, " + "SP" + "ECTRUM").empty());
}

}  // namespace
