// 01_lut_memory -- thesis Table 2: equiangular map size and memory, formula and measured.
//
// Inputs: none. Outputs: OUT/01_lut_memory/lut_memory.csv, meta.json.
// Command: build/experiments/exp_01_lut_memory --out results
// For p = 1, 0.5, 0.1, 0.05 deg and float / double storage: node count by the formula
// (180/p + 1)(360/p), bytes by the formula, bytes allocated by the map (capacity x size), and the
// resident-set growth when the map is created (every node is written, so every page is touched).
#include <fstream>
#include <unistd.h>

#include "experiment_support.hpp"
#include "impinge/radial_distance_map.hpp"

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
void measure(CsvWriter& csv, double p, std::int64_t thesis_nodes, double thesis_mb) {
  const EquiangularGrid g(p);
  const std::int64_t formula = (std::int64_t(std::llround(180 / p)) + 1) * std::int64_t(std::llround(360 / p));
  const long before = resident_bytes();
  std::size_t allocated = 0;
  long rss = 0;
  {
    RadialDistanceMapT<Scalar> map(g);
    allocated = map.bytes();
    rss = resident_bytes() - before;
  }
  csv.row(p, sizeof(Scalar) == 4 ? "float" : "double", formula, g.num_nodes(), int(sizeof(Scalar)),
          map_bytes_formula(formula, sizeof(Scalar)), std::int64_t(allocated), std::int64_t(rss),
          double(allocated) / (1024.0 * 1024.0), thesis_nodes, thesis_mb);
}
}  // namespace

int main(int argc, char** argv) {
  const Args args = parse_args(argc, argv, "01_lut_memory: thesis Table 2, map sizes and memory");
  const std::string dir = experiment_dir(args, "01_lut_memory");
  CsvWriter csv(dir + "/lut_memory.csv",
                {"precision_deg", "storage", "nodes_formula", "nodes", "bytes_per_node", "bytes_formula",
                 "bytes_allocated", "rss_growth_bytes", "memory_mib", "thesis_nodes", "thesis_memory_mb"});
  // Thesis Table 2 (double storage): nodes and "MB" (the thesis' MB are MiB: 65,160 x 8 / 2^20 = 0.497).
  const struct {
    double p;
    std::int64_t nodes;
    double mb;
  } table2[] = {{1, 65160, 0.497}, {0.5, 259920, 1.98}, {0.1, 6483600, 49.5}, {0.05, 25927200, 197.8}};
  int k = 0;
  for (const auto& row : table2) {
    progress("01_lut_memory", ++k, 4, "p=" + std::to_string(row.p));
    measure<float>(csv, row.p, row.nodes, row.mb);
    measure<double>(csv, row.p, row.nodes, row.mb);
  }
  write_meta(dir, args, {{"precisions_deg", {1, 0.5, 0.1, 0.05}}, {"storages", {"float", "double"}},
                         {"thesis_source", "thesis Table 2 (sec. 3.4), double storage"}});
  return 0;
}
