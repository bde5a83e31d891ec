#pragma once
// Private to libcore: the cone set-up of the rasteriser (rasterize.cpp): a triangle's corners in
// spherical coordinates about the COR and the precision-independent cone through them
// (triangle_cone.hpp). Thesis sec. 3.2, Algorithm 1 (the triangle's projection into the grid);
// cones: issue 4.

#include <Eigen/Core>
#include <vector>

#include "impinge/core/mesh.hpp"
#include "impinge/core/spherical_frame.hpp"
#include "impinge/sampling/triangle_cone.hpp"

namespace impinge::detail {

using V3 = Eigen::Vector3d;

/// Wrap an angle difference into (-pi, pi].
inline double wrap_pi(double a) {
  while (a > kPi) a -= 2 * kPi;
  while (a <= -kPi) a += 2 * kPi;
  return a;
}

/// True when v lies on the z axis (a pole direction), to rounding.
inline bool on_axis(const V3& v) { return v.x() * v.x() + v.y() * v.y() <= 1e-24 * v.squaredNorm(); }

/// A triangle corner relative to the COR with its spherical coordinates, computed once per
/// mesh vertex (theta of a point on the axis is 0).
struct Corner {
  V3 p;  ///< position relative to the COR, mm
  double d, phi, theta;
  bool axis;                                               ///< on the z axis (a pole vertex, thesis case 1)
  V3 u() const { return d > 0 ? V3(p / d) : V3::Zero(); }  ///< unit direction
};
/// Angles by fast_angles.hpp (within 1e-13 rad of libm's): they only place bounding boxes
/// (padded by 1e-4 steps) and feed linear mode's interpolation.
Corner corner(const V3& v);

/// Whether direction d lies in the cone of corners a, b, c (det = a . (b x c) != 0).
inline bool in_cone(const V3& a, const V3& b, const V3& c, double det, const V3& d) {
  const double s = det > 0 ? 1.0 : -1.0;
  return s * d.dot(b.cross(c)) >= 0 && s * d.dot(c.cross(a)) >= 0 && s * d.dot(a.cross(b)) >= 0;
}

/// The precision-independent set-up of the cone through corners (ka, kb, kc) with
/// det = a . (b x c) != 0 (triangle_cone.hpp). `north` / `south`: the cone holds that pole.
TriangleCone make_cone(const Corner& ka, const Corner& kb, const Corner& kc, double det, bool north, bool south);

/// Spherical coordinates of every vertex relative to `cor` (a vertex is shared by about six
/// triangles). Reused between calls on this thread: a fresh multi-megabyte buffer would be
/// page-faulted in on every call.
const std::vector<Corner>& vertex_corners(const TriangleMesh& mesh, const Eigen::Vector3d& cor);

/// Appends to `out` the cones of faces[begin, end) of `mesh` (in that order), whose vertices' corners are
/// `corners` (vertex_corners), skipping those whose plane passes through the COR; returns how many were
/// skipped. triangle_cones over all the faces at once, or a range at a time (rasterize's streamed plan).
std::int64_t append_triangle_cones(const TriangleMesh& mesh, const std::vector<Corner>& corners,
                                   const std::vector<std::int32_t>& faces, std::size_t begin, std::size_t end,
                                   std::vector<TriangleCone>& out);

}  // namespace impinge::detail
