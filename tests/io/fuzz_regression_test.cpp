// The fuzz harnesses (tests/fuzz/fuzz_inputs.hpp) on every seed and every input the fuzzer ever
// found (tests/fuzz/regressions/TARGET/): seeds must load, found inputs must be accepted or refused
// with impinge::Error naming the file, never crash, hang or break a loader's guarantee. Under
// ./test --sanitize this replays them with AddressSanitizer and UndefinedBehaviorSanitizer.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "fuzz/fuzz_inputs.hpp"

namespace fs = std::filesystem;
using impinge::fuzz::Outcome;

namespace {
std::vector<std::uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> out;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

const fs::path kFuzzDir = fs::path(IMPINGE_SOURCE_DIR) / "tests" / "fuzz";
}  // namespace

class FuzzInputs : public ::testing::TestWithParam<const char*> {};

TEST_P(FuzzInputs, SeedsLoad) {
  const auto seeds = files_in(kFuzzDir / "seeds" / GetParam());
  ASSERT_GE(seeds.size(), 2u);
  for (const fs::path& p : seeds) {
    const auto bytes = read_bytes(p);
    const Outcome o = impinge::fuzz::run_input(GetParam(), bytes.data(), bytes.size());
    EXPECT_EQ(o.kind, Outcome::accepted) << p << ": " << o.message;
  }
}

TEST_P(FuzzInputs, FoundInputsAreRefusedOrAcceptedNeverBugs) {
  for (const fs::path& p : files_in(kFuzzDir / "regressions" / GetParam())) {
    const auto bytes = read_bytes(p);
    const Outcome o = impinge::fuzz::run_input(GetParam(), bytes.data(), bytes.size());
    EXPECT_NE(o.kind, Outcome::bug) << p << ": " << o.message;
    // A refusal names the file the loader was given.
    if (o.kind == Outcome::refused) {
      EXPECT_NE(o.message.find("impinge-fuzz-"), std::string::npos) << p << ": " << o.message;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Parsers, FuzzInputs, ::testing::Values("mesh", "subject", "motion"));

// The harness itself can fail: a loader guarantee broken, or a foreign exception, is a bug.
TEST(FuzzHarness, TruncatedSeedsAreRefusedWithTheFileNamed) {
  for (const char* target : {"mesh", "motion"}) {
    for (const fs::path& p : files_in(kFuzzDir / "seeds" / target)) {
      auto bytes = read_bytes(p);
      if (bytes.size() < 40) continue;
      // Cut inside the body: what is left is either still a valid file or a clear refusal.
      for (std::size_t cut : {bytes.size() / 3, bytes.size() / 2, bytes.size() - 7}) {
        const Outcome o = impinge::fuzz::run_input(target, bytes.data(), cut);
        EXPECT_NE(o.kind, Outcome::bug) << p << " cut at " << cut << ": " << o.message;
      }
    }
  }
}
