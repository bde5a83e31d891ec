// libFuzzer entry point for one harness of fuzz_inputs.hpp, chosen at compile time
// (IMPINGE_FUZZ_TARGET: "mesh", "subject" or "motion"). A bug outcome aborts, so libFuzzer saves the
// input; built and run by tools/fuzz.
#include <cstdio>
#include <cstdlib>

#include "fuzz_inputs.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const impinge::fuzz::Outcome o = impinge::fuzz::run_input(IMPINGE_FUZZ_TARGET, data, size);
  if (o.kind == impinge::fuzz::Outcome::bug) {
    std::fprintf(stderr, "impinge fuzz (%s): %s\n", IMPINGE_FUZZ_TARGET, o.message.c_str());
    std::abort();
  }
  return 0;
}
