// 01_lut_memory -- thesis Tables 2, 6, 7 and Fig. 49's counts: map sizes and memory of RSID
// (equiangular) and USID (helix), formula and measured; node density against latitude.
//
// Inputs: none. Outputs: OUT/01_lut_memory/
//   lut_memory.csv    one row per scheme x resolution x storage (float / double)
//   helix_match.csv   Table 6: k matched to the equator's node count of each precision
//   schemes.csv       every registered scheme at the coarsest resolution whose largest node spacing is at
//                     most 1, 0.5, 0.1 and 0.05 deg (resolution_for_spacing): nodes, float bytes, node
//                     count relative to the equiangular grid of that spacing (issue 12)
//   sparse.csv        every subject (the real ones under --data and a generated 3k hip) x body x registered
//                     scheme at largest node spacings 0.5, 0.1 and 0.05 deg: the map's dense bytes and its
//                     sparse bytes (make_sparse: only the 256-node tiles that hold a surface, any distance;
//                     the same look-ups bit for bit), tiles stored of all, nodes with a surface (issue 12)
//   density.csv       nodes per steradian in 1-deg latitude bands centred on whole degrees, both schemes at
//                     1 deg / k = 229
//   meta.json
// Command: build/experiments/exp_01_lut_memory --out results [--data ../shared/data/hips] [--quick]
#include <unistd.h>

#include <fstream>

#include "experiment_support.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/maps/radial_distance_map.hpp"
#include "impinge/sampling/sampling.hpp"
#include "impinge/schemes/equiangular_grid.hpp"
#include "impinge/schemes/helix_scheme.hpp"

using namespace impinge;
using namespace impinge::experiment;

namespace {
long resident_bytes() {
  std::ifstream in("/proc/self/statm");
  long size = 0, resident = 0;
  in >> size >> resident;
  return resident * sysconf(_SC_PAGESIZE);
}

template <typename Scalar>
void measure(CsvWriter& csv, const std::shared_ptr<const SamplingScheme>& scheme, std::int64_t nodes_formula,
             std::int64_t thesis_nodes, double thesis_mb, double matched_precision) {
  const long before = resident_bytes();
  std::size_t allocated = 0;
  long rss = 0;
  {
    RadialDistanceMapT<Scalar> map(scheme);
    allocated = map.bytes();
    rss = resident_bytes() - before;
  }
  csv.row(scheme->name(), scheme->resolution(), matched_precision, sizeof(Scalar) == 4 ? "float" : "double",
          nodes_formula, scheme->num_nodes(), int(sizeof(Scalar)), map_bytes_formula(nodes_formula, sizeof(Scalar)),
          std::int64_t(allocated), std::int64_t(rss), double(allocated) / (1024.0 * 1024.0), thesis_nodes, thesis_mb);
}
// Thesis Table 2 (equiangular) and Tables 6-7 (helix): nodes and memory of both storages at each
// precision, and the helix matched to each precision.
void thesis_tables(const std::string& dir) {
  CsvWriter csv(dir + "/lut_memory.csv", {"scheme", "resolution", "matched_precision_deg", "storage", "nodes_formula",
                                          "nodes", "bytes_per_node", "bytes_formula", "bytes_allocated",
                                          "rss_growth_bytes", "memory_mib", "thesis_nodes", "thesis_memory_mb"});
  CsvWriter match(
      dir + "/helix_match.csv",
      {"precision_deg", "equiangular_equator_nodes", "turns", "thesis_turns", "helix_node_spacing_deg",
       "helix_equator_nodes", "thesis_helix_equator_nodes", "helix_nodes", "equiangular_nodes", "node_ratio"});
  // Thesis Table 2 (equiangular, double) and Tables 6-7 (helix, double). The thesis' "MB" are
  // MiB: 65,160 x 8 / 2^20 = 0.497.
  const struct {
    double p;
    std::int64_t nodes;
    double mb;
    double k;
    std::int64_t helix_nodes;
    double helix_mb;
    std::int64_t helix_equator;
  } thesis[] = {{1, 65160, 0.497, 229, 52441, 0.40, 360},
                {0.5, 259920, 1.98, 458, 209764, 1.60, 720},
                {0.1, 6483600, 49.5, 2292, 5253264, 40.07, 3601},
                {0.05, 25927200, 197.8, 4584, 21013056, 160.32, 7201}};
  int step = 0;
  for (const auto& t : thesis) {
    progress("01_lut_memory", ++step, 4, "p=" + std::to_string(t.p));
    const std::int64_t n = std::llround(180 / t.p);
    const std::int64_t eq_formula = (n + 1) * (2 * n);
    // Table 6: the helix whose equator carries as many nodes as the grid's equator row (360/p):
    // about pi k / 2 nodes per turn at the equator (spacing ~4/k), so k = round(720 / (pi p)).
    const double k = matched_helix_turns(t.p);
    const auto eq = make_scheme("equiangular", t.p);
    const auto hx = std::make_shared<HelixScheme>(k);
    const double helix_equator = 2 * kPi / hx->node_spacing();
    match.row(t.p, 2 * n, k, t.k, hx->node_spacing() * kRadToDeg, helix_equator, t.helix_equator, hx->num_nodes(),
              eq->num_nodes(), double(hx->num_nodes()) / double(eq->num_nodes()));
    measure<float>(csv, eq, eq_formula, t.nodes, t.mb, t.p);
    measure<double>(csv, eq, eq_formula, t.nodes, t.mb, t.p);
    const std::int64_t w = std::int64_t(k) * std::int64_t(k);
    measure<float>(csv, hx, w, t.helix_nodes, t.helix_mb, t.p);
    measure<double>(csv, hx, w, t.helix_nodes, t.helix_mb, t.p);
  }
}

// Every registered scheme at equal largest node spacing (issue 12): a new scheme appears here with no
// change to this file.
void schemes_table(const std::string& dir) {
  CsvWriter sc(dir + "/schemes.csv", {"spacing_deg", "scheme", "resolution_name", "resolution", "nodes",
                                      "max_node_spacing_deg", "float_bytes", "nodes_over_equiangular"});
  for (double p : {1.0, 0.5, 0.1, 0.05}) {
    const double eq_nodes = double(make_scheme("equiangular", resolution_for_spacing("equiangular", p))->num_nodes());
    for (const auto& [name, unit] : scheme_names()) {
      const auto s = make_scheme(name, resolution_for_spacing(name, p));
      sc.row(p, name, unit, s->resolution(), s->num_nodes(), s->max_node_spacing() * kRadToDeg,
             s->num_nodes() * std::int64_t(sizeof(float)), double(s->num_nodes()) / eq_nodes);
    }
  }
}

// Dense against sparse storage of real maps (issue 12).
void sparse_table(const Args& args, const std::string& dir) {
  CsvWriter sp(dir + "/sparse.csv", {"subject", "body", "scheme", "resolution", "spacing_deg", "nodes",
                                     "nodes_covered", "tiles_stored", "tiles_total", "dense_bytes", "sparse_bytes"});
  const std::vector<Subject> subjects = load_subjects(args, {3000});
  std::vector<double> spacings{0.5, 0.1};
  if (!args.quick) spacings.push_back(0.05);
  int done = 0;
  for (const Subject& sub : subjects) {
    progress("01_lut_memory", ++done, int(subjects.size()), "sparse maps of " + sub.name);
    const Eigen::Vector3d cor = subject_cor(sub);
    for (double p : spacings)
      for (const auto& [name, unit] : scheme_names()) {
        const auto scheme = make_scheme(name, resolution_for_spacing(name, p));
        for (int body = 0; body < 2; ++body) {
          RadialDistanceMap m(scheme);
          sample_surface(body == 0 ? sub.femur : sub.pelvis, cor, SamplingOptions{}, m);
          const std::size_t dense = m.bytes();
          m.make_sparse();
          sp.row(sub.name, body == 0 ? "femur" : "pelvis", name, scheme->resolution(), p, m.num_nodes(),
                 m.nodes_covered(), m.tiles_stored(), m.tiles_total(), std::int64_t(dense), std::int64_t(m.bytes()));
        }
      }
  }
}

// Node density against latitude (Fig. 49 compares the two at 1 deg): nodes per steradian in
// 1-deg bands of phi centred on whole degrees ([b - 0.5, b + 0.5), halved at the poles), so that
// the equiangular rows, which lie on whole degrees, sit mid-band and rounding cannot move a row into
// the next band (bands with edges on whole degrees showed empty and doubled bands).
void density_table(const std::string& dir) {
  CsvWriter dens(dir + "/density.csv",
                 {"scheme", "resolution", "phi_low_deg", "phi_high_deg", "nodes", "band_sr", "nodes_per_sr"});
  const EquiangularGrid eq(1);
  const HelixScheme hx(229);
  for (const SamplingScheme* s : std::initializer_list<const SamplingScheme*>{&eq, &hx}) {
    std::vector<std::int64_t> count(181, 0);
    std::vector<double> phi(4096), theta(4096);
    for (std::int64_t first = 0; first < s->num_nodes(); first += 4096) {
      const std::int64_t c = std::min<std::int64_t>(4096, s->num_nodes() - first);
      s->node_angles(first, c, phi.data(), theta.data());
      for (std::int64_t j = 0; j < c; ++j)
        ++count[std::min<std::size_t>(180, static_cast<std::size_t>(std::floor(phi[j] * kRadToDeg + 0.5)))];
    }
    for (int b = 0; b <= 180; ++b) {
      const double lo = std::max(0.0, b - 0.5), hi = std::min(180.0, b + 0.5);
      const double sr = 2 * kPi * (std::cos(lo * kDegToRad) - std::cos(hi * kDegToRad));
      dens.row(s->name(), s->resolution(), lo, hi, count[b], sr, double(count[b]) / sr);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "01_lut_memory: thesis Tables 2, 6, 7; map sizes and memory");
  const std::string dir = experiment_dir(args, "01_lut_memory");
  thesis_tables(dir);
  schemes_table(dir);
  sparse_table(args, dir);
  density_table(dir);
  write_meta(dir, args,
             {{"precisions_deg", {1, 0.5, 0.1, 0.05}},
              {"turns", {229, 458, 2292, 4584}},
              {"storages", {"float", "double"}},
              {"thesis_source", "thesis Table 2 (sec. 3.4), Tables 6-7 and Fig. 49 (sec. 4.4), double storage"},
              {"matching", "k = round(720 / (pi p)): helix equator nodes (2 pi / spacing) = 360 / p"}});
  return 0;
}
