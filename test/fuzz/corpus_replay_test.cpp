// The fuzz targets as regression tests in `make test` (gcc, no sanitizers, no libFuzzer): every
// checked-in corpus input and every former crash input is replayed, then a few thousand seeded
// random and mutated inputs. `make fuzz` runs the same targets under libFuzzer with ASan and UBSan.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "fuzz_check.h"

namespace hrg_gyro {
namespace fuzz {
namespace {

namespace fs = std::filesystem;
using Target = int (*)(const std::uint8_t*, std::size_t);

std::vector<std::vector<std::uint8_t>> readInputs(const fs::path& dir) {
  std::vector<std::vector<std::uint8_t>> inputs;
  if (!fs::is_directory(dir)) return inputs;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    std::ifstream in(file, std::ios::binary);
    inputs.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return inputs;
}

// Replays corpus and regressions, then mutates corpus inputs (byte flips, cuts, splices) and adds
// pure random inputs, all from a fixed seed so that a failure reproduces.
void replay(const std::string& name, Target target, std::size_t min_corpus) {
  const fs::path root = fs::path(HRG_FUZZ_DIR);
  const auto corpus = readInputs(root / "corpus" / name);
  ASSERT_GE(corpus.size(), min_corpus) << "corpus of " << name << " missing or too small";
  for (const auto& input : corpus) target(input.data(), input.size());
  for (const auto& input : readInputs(root / "regressions" / name)) target(input.data(), input.size());

  std::mt19937_64 rng(20261121);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int i = 0; i < 3000; ++i) {
    std::vector<std::uint8_t> input = corpus[rng() % corpus.size()];
    switch (i % 4) {
      case 0:  // flip a few bytes
        for (int k = 0, n = 1 + rng() % 8; k < n && !input.empty(); ++k) input[rng() % input.size()] = byte(rng);
        break;
      case 1:  // cut
        input.resize(input.empty() ? 0 : rng() % input.size());
        break;
      case 2: {  // splice two inputs
        const auto& other = corpus[rng() % corpus.size()];
        const std::size_t at = input.empty() ? 0 : rng() % input.size();
        input.resize(at);
        input.insert(input.end(), other.begin() + (other.empty() ? 0 : rng() % other.size()), other.end());
        break;
      }
      default:  // random
        input.resize(rng() % 512);
        for (auto& b : input) b = byte(rng);
    }
    target(input.data(), input.size());
  }
}

TEST(FuzzCorpus, ParameterFileLoaderHoldsItsInvariants) { replay("parameter_file", parameterFileTarget, 8); }

TEST(FuzzCorpus, SampleProcessingHoldsItsInvariants) { replay("sample_processing", sampleProcessingTarget, 6); }

}  // namespace
}  // namespace fuzz
}  // namespace hrg_gyro
