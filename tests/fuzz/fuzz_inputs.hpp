#pragma once
// The fuzzed inputs: the mesh loader (load_mesh through assimp), subject.json (load_subject) and
// motion files (load_motion, CSV and OpenSim). Each harness writes the bytes to a file, as a user
// would hand them over, and calls the loader. A loader may accept the input or refuse it with
// impinge::Error; anything else (another exception, a crash, a sanitizer report, an accepted result
// that breaks the loader's documented guarantees) is a bug.
// Shared by the libFuzzer drivers (tools/fuzz) and the regression test that replays the seeds and
// every crash found (tests/fuzz_regression_test.cpp).

#include <cstddef>
#include <cstdint>
#include <string>

namespace impinge::fuzz {

/// What one input did.
struct Outcome {
  enum Kind { accepted, refused, bug } kind = accepted;
  std::string message;  ///< impinge::Error's message when refused; what went wrong when bug
};

/// Mesh loader. The first byte picks the file extension (.ply, .stl, .obj, .off by its value mod 4);
/// the rest is the file. Accepted meshes must have finite vertices, indices in range and no
/// degenerate face (load_mesh's guarantees).
Outcome mesh_input(const std::uint8_t* data, std::size_t size);

/// subject.json: the bytes are the file. Accepted subjects must name a side, a frame and two mesh
/// paths, and every landmark must be finite.
Outcome subject_input(const std::uint8_t* data, std::size_t size);

/// Motion file. The first byte picks the format (.mot, .sto or .csv by its value mod 3) and the side
/// (right if bit 7 is clear); the rest is the file. Accepted motions must have as many times as poses,
/// at least one frame, finite angles and non-decreasing times.
Outcome motion_input(const std::uint8_t* data, std::size_t size);

/// The harness by name ("mesh", "subject", "motion"); throws std::invalid_argument for another.
Outcome run_input(const std::string& target, const std::uint8_t* data, std::size_t size);

}  // namespace impinge::fuzz
