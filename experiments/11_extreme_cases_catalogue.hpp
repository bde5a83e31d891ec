#pragma once
// 11_extreme_cases, the catalogue (cases 2 to 6): closed spheres about the COR built to stress one
// thing each (a vertex, edge or face on the pole, an edge on the seam, slivers of aspect 1e6,
// duplicate and inverted triangles, scales of 1e-3 and 1e5 mm, a placement 1e5 mm from the origin
// with double and float input, precision 0.01 deg, a million triangles), touching and deeply
// penetrating bones, and the stiff numerics (sphere fits on small caps, the helix arc length from
// k = 2 to 1e5 and at the poles, the conchoid inversion at its end points). One row per case,
// variant, scheme, mode and storage in cases.csv: the measured error against its exact reference,
// the bound claimed, pass or fail.
#include <string>

#include "experiment_support.hpp"

namespace impinge::experiment {

/// Run the catalogue into DIR/cases.csv (header: case, variant, scheme, resolution, mode, storage,
/// triangles, compared, holes, max_abs, bound, unit, pass, note). Returns the number of steps run
/// (the progress count recorded in meta.json).
int run_extreme_case_catalogue(const Args& args, const std::string& dir);

}  // namespace impinge::experiment
