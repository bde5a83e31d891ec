#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "clinical/rom_gap_scanner.hpp"
#include "impinge/clinical/rom.hpp"
#include "impinge/core/error.hpp"
#include "impinge/core/interrupt.hpp"

namespace impinge {
using namespace rom_detail;

namespace {
std::vector<double> envelope_axis(double lo, double hi, double step, const char* name) {
  require(std::isfinite(lo) && std::isfinite(hi) && hi >= lo, std::string("rom envelope: bad ") + name + " range");
  const double n = (hi - lo) / step;
  require(std::abs(n - std::round(n)) < 1e-6 && n < 1e6,
          std::string("rom envelope: the ") + name + " range is not a whole number of steps");
  std::vector<double> a;
  for (long k = 0; k <= std::lround(n); ++k) a.push_back(lo + double(k) * step);
  return a;
}
// A box of grid indices [lo, hi] per axis.
struct Box {
  std::array<int, 3> lo, hi;
};

// The cells of the coarse lattice (every `coarse` steps, the last cut at the axis' end) of a grid of
// n[a] poses per axis.
std::vector<Box> coarse_boxes(const std::array<int, 3>& n, int coarse) {
  std::array<std::vector<int>, 3> cuts;
  for (int a = 0; a < 3; ++a) {
    for (int v = 0; v < n[a] - 1; v += coarse) cuts[a].push_back(v);
    cuts[a].push_back(n[a] - 1);
  }
  std::vector<Box> boxes;
  auto at = [](const std::vector<int>& c, std::size_t k) { return c[std::min(k, c.size() - 1)]; };
  for (std::size_t x = 0; x + 1 < std::max<std::size_t>(cuts[0].size(), 2); ++x)
    for (std::size_t y = 0; y + 1 < std::max<std::size_t>(cuts[1].size(), 2); ++y)
      for (std::size_t z = 0; z + 1 < std::max<std::size_t>(cuts[2].size(), 2); ++z)
        boxes.push_back({{at(cuts[0], x), at(cuts[1], y), at(cuts[2], z)},
                         {at(cuts[0], x + 1), at(cuts[1], y + 1), at(cuts[2], z + 1)}});
  return boxes;
}

// Split every axis of `b` wider than one step at its middle, appending the parts to `out`; a box of
// single steps has no parts (every corner is known).
void split_box(const Box& b, std::vector<Box>& out) {
  std::array<std::array<int, 3>, 3> cut;  // per axis: lo, mid, hi (mid = hi when not split)
  std::array<int, 3> parts;
  for (int a = 0; a < 3; ++a) {
    const int w = b.hi[a] - b.lo[a];
    cut[a] = {b.lo[a], w > 1 ? b.lo[a] + w / 2 : b.hi[a], b.hi[a]};
    parts[a] = w > 1 ? 2 : 1;
  }
  if (parts[0] * parts[1] * parts[2] == 1) return;
  for (int x = 0; x < parts[0]; ++x)
    for (int y = 0; y < parts[1]; ++y)
      for (int z = 0; z < parts[2]; ++z)
        out.push_back({{cut[0][x], cut[1][y], cut[2][z]},
                       {parts[0] == 1 ? cut[0][2] : cut[0][x + 1], parts[1] == 1 ? cut[1][2] : cut[1][y + 1],
                        parts[2] == 1 ? cut[2][2] : cut[2][z + 1]}});
}

// The index of pose (i, j, k) in a grid of n[a] poses per axis (the last axis fastest).
std::size_t grid_index(const std::array<int, 3>& n, int i, int j, int k) {
  return (std::size_t(i) * n[1] + j) * n[2] + k;
}

// The index of box b's corner c (bit a set: the box's hi end on axis a, else its lo end).
std::size_t corner_index(const std::array<int, 3>& n, const Box& b, int c) {
  return grid_index(n, (c & 1) ? b.hi[0] : b.lo[0], (c & 2) ? b.hi[1] : b.lo[1], (c & 4) ? b.hi[2] : b.lo[2]);
}

// Appends the corners of box b not yet known (state < 0) to `list` and marks them listed (state 2).
void list_unknown_corners(const Box& b, const std::array<int, 3>& n, std::vector<std::int8_t>& state,
                          std::vector<std::size_t>& list) {
  for (int c = 0; c < 8; ++c) {
    const std::size_t p = corner_index(n, b, c);
    if (state[p] < 0) {
      state[p] = 2;  // listed
      list.push_back(p);
    }
  }
}

// The next level's boxes: each box whose corners (all scanned) disagree, split; those whose corners agree (all
// contact or all valid) are appended to `uniform` instead.
std::vector<Box> split_mixed_boxes(const std::vector<Box>& boxes, const std::array<int, 3>& n,
                                   const std::vector<std::int8_t>& state, std::vector<Box>& uniform) {
  std::vector<Box> next;
  for (const Box& b : boxes) {
    int sum = 0;
    for (int c = 0; c < 8; ++c) sum += state[corner_index(n, b, c)];
    if (sum == 0 || sum == 8) {
      uniform.push_back(b);
      continue;
    }
    split_box(b, next);
  }
  return next;
}

// Every pose of each uniform box not yet known takes the state of the box's corners.
void fill_uniform_boxes(const std::vector<Box>& uniform, const std::array<int, 3>& n, std::vector<std::int8_t>& state) {
  for (const Box& b : uniform) {
    const std::int8_t v = state[grid_index(n, b.lo[0], b.lo[1], b.lo[2])];
    for (int i = b.lo[0]; i <= b.hi[0]; ++i)
      for (int j = b.lo[1]; j <= b.hi[1]; ++j)
        for (int k = b.lo[2]; k <= b.hi[2]; ++k)
          if (state[grid_index(n, i, j, k)] < 0) state[grid_index(n, i, j, k)] = v;
  }
}
}  // namespace

RomEnvelope rom_envelope(const HipJoint& hip, const RomEnvelopeOptions& e, const RomOptions& o,
                         const RomBaseline& base) {
  check(o);
  check_metric(hip.joint(), o);
  require(e.step_deg > 0, "rom envelope: need step > 0");
  check_in_range("RomEnvelopeOptions::coarse_steps", e.coarse_steps, RomEnvelopeOptions::kCoarseStepsRange);
  RomEnvelope out;
  out.flexion_deg = envelope_axis(e.flexion_min_deg, e.flexion_max_deg, e.step_deg, "flexion");
  out.adduction_deg = envelope_axis(e.adduction_min_deg, e.adduction_max_deg, e.step_deg, "adduction");
  out.internal_rotation_deg =
      envelope_axis(e.internal_rotation_min_deg, e.internal_rotation_max_deg, e.step_deg, "internal rotation");
  const std::array<int, 3> n{static_cast<int>(out.flexion_deg.size()), static_cast<int>(out.adduction_deg.size()),
                             static_cast<int>(out.internal_rotation_deg.size())};
  out.poses = std::int64_t(n[0]) * n[1] * n[2];
  std::vector<std::int8_t> state(static_cast<std::size_t>(out.poses), -1);  // -1 unknown, 0 contact, 1 valid
  const Joint& joint = hip.joint();
  // The per-vertex test at every pose (rom.hpp: the exact test would cost some 300 times as much here and move
  // the envelope's boundary by a fraction of a degree, well within its step).
  RomOptions per_vertex = o;
  per_vertex.exact_contact = false;
  const std::shared_ptr<const RomSearchBounds> bounds = bounds_for(joint, per_vertex, base);

  // Scan the listed poses on all cores; each thread keeps its scanner.
  std::int64_t looked = 0, skipped = 0;
  auto scan_all = [&](const std::vector<std::size_t>& poses) {
    const auto m = static_cast<std::int64_t>(poses.size());
    std::string error;  // the first error of any thread, thrown after the parallel region
#pragma omp parallel reduction(+ : looked, skipped)
    {
      GapScanner scan(joint, base, bounds.get(), per_vertex);
#pragma omp for schedule(dynamic, 64)
      for (std::int64_t q = 0; q < m; ++q) {
        const std::size_t p = poses[static_cast<std::size_t>(q)];
        const std::size_t k = p % n[2], j = (p / n[2]) % n[1], i = p / (std::size_t(n[1]) * n[2]);
        const Eigen::Matrix3d R =
            hip.femur_rotation(PoseAngles{out.flexion_deg[i], out.adduction_deg[j], out.internal_rotation_deg[k]});
        try {
          interruption_point();  // a front end's stop (Ctrl-C in Python)
          state[p] = scan(R, hip.joint_translation(R), false).gap > cut_of(o) ? 1 : 0;
        } catch (const std::exception& err) {
#pragma omp critical(rom_envelope_error)
          if (error.empty()) error = err.what();
        }
      }
      looked += scan.vertices_looked_up();
      skipped += scan.vertices_skipped();
    }
    require(error.empty(), error);
    out.poses_evaluated += m;
  };
  // The coarse lattice's cells, then their parts where the corners disagree, scanning the corners not yet known.
  std::vector<Box> boxes = coarse_boxes(n, e.coarse_steps);
  std::vector<Box> uniform;  // boxes whose corners agree: filled at the end
  while (!boxes.empty()) {
    std::vector<std::size_t> list;
    for (const Box& b : boxes) list_unknown_corners(b, n, state, list);
    scan_all(list);
    boxes = split_mixed_boxes(boxes, n, state, uniform);
  }
  fill_uniform_boxes(uniform, n, state);
  out.valid.resize(state.size());
  for (std::size_t p = 0; p < state.size(); ++p) {
    require(state[p] == 0 || state[p] == 1, "rom envelope: internal error, a pose was left undecided");
    out.valid[p] = static_cast<std::uint8_t>(state[p]);
  }
  out.vertices_looked_up = looked;
  out.vertices_skipped = skipped;
  return out;
}

}  // namespace impinge
