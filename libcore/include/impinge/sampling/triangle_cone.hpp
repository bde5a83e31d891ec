#pragma once
/// @file triangle_cone.hpp
/// The part of a triangle's exact-mode rasterisation set-up that does not depend on the map's
/// precision (faster rasteriser; not in the thesis). A face-culling plan
/// (raster_plan.hpp) holds one per kept triangle, made once per mesh and COR, so that a
/// rasterisation only turns these angles into rows, columns and row spans.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "impinge/core/mesh.hpp"

namespace impinge {

/// The cone from the COR through one triangle (a, b, c), corners relative to the COR in mm.
/// A direction u lies in the cone when e_k . u >= 0 for the three oriented edge normals; the
/// ray along unit u meets the triangle's plane at adet / (n . u), n = e_0 + e_1 + e_2 (the
/// oriented face normal, computed as (b - a) x (c - a), which keeps the digits that the sum of
/// the three edge normals loses for a small triangle far from the COR).
///
/// Row spans: on the row of polar angle phi, edge k's constraint
/// sin(phi) rho_k cos(theta - alpha_k) + cos(phi) e_k.z >= 0 (rho_k = |(e_k.x, e_k.y)|) holds on
/// the azimuths within acos(k_k cot(phi)) of alpha_k, where k_k = -e_k.z / rho_k. rasterize()
/// tests only the columns of that arc, widened by pad_k / sqrt(sin(phi)) radians (pad_k =
/// 2e-7 / sqrt(rho_k / |e_k|)) plus 3.1e-8 rad (fast_acos_coarse's error and 1e-9) and
/// 1e-6 columns: much more than the rounding of
/// a node's edge functions can move a covered node, even where the edge is nearly tangent to
/// the row (where the arc's end moves by the square root of that rounding), so the spans skip
/// only nodes that the full box test rejects. The same widening taken inwards gives an inner
/// span whose nodes the full test certainly accepts; on a row where both spans hold the same
/// nodes (all but about 0.1 % of rows) the rasteriser skips the edge functions and computes only
/// the distances. The maps are the same, node for node (tested).
/// Angle (rad) by which a node direction may lie outside an edge's great circle and still count as
/// inside it: e_k . u >= -kEdgeAngleTolerance |e_k|. Shared edges are watertight without it (a
/// negated normal negates the edge function exactly), but at a shared vertex the edge functions of
/// the incident triangles are rounded independently, and a node through the vertex could be
/// covered by none of them (experiment 11 found such holes on meshes whose vertices lie on node
/// directions). The tolerance covers the rounding of the edge normals (up to about 1e-10 rad for
/// sliver edges of aspect ratio 1e6) and is far below any node spacing: the overlap it gives two
/// neighbours is 1e-9 rad (2.2e-8 mm at 22 mm), where both planes give the same distance to rounding.
inline constexpr double kEdgeAngleTolerance = 1e-9;

struct TriangleCone {
  double e[9];                  ///< oriented edge normals e_0, e_1, e_2 (mm^2), x y z each
  double bias[3];               ///< kEdgeAngleTolerance |e_k| (mm^2): inside edge k when e_k . u >= -bias[k]
  double adet;                  ///< |a . (b x c)| (mm^3), six times the tetrahedron's volume
  double n[3];                  ///< oriented face normal (mm^2): n . u > 0 inside the cone
  double phi_min, phi_max;      ///< polar range (rad) of the spherical triangle, poles included
  double theta_min, theta_max;  ///< azimuth range (rad) unwrapped around corner a (theta_min may
                                ///< be < 0, theta_max >= 2 pi); unused when full_theta
  double alpha[3];              ///< azimuth (rad, [0, 2 pi]) of each edge normal's (x, y)
  double k[3];                  ///< -e_k.z / rho_k (arc half-width acos(k cot phi))
  double pad[3];                ///< 2e-7 / sqrt(rho_k / |e_k|) (rad at sin(phi) = 1)
  bool span_edge[3];            ///< rho_k > 1e-12 |e_k| (else the edge bounds no span)
  bool full_theta;              ///< every column: the cone holds a pole, has a corner on the axis
                                ///< or spans 180 deg of azimuth or more
  bool north, south;            ///< the cone holds the pole phi = 0 / phi = pi
  bool seam;                    ///< the azimuth range crosses theta = 0/360
};

/// Cones of the triangles `faces` of `mesh` (in that order) about `cor` (mm), skipping those
/// whose plane passes through the COR (|det| <= 1e-12 |a| |b| |c|: they cover no direction),
/// which are counted in `edge_on` when not null. Every face index must be valid (the caller
/// validated the mesh). Cost O(|faces|). Source: thesis sec. 3.2 (the cone test of Algorithm 1
/// in exact form), row spans.
std::vector<TriangleCone> triangle_cones(const TriangleMesh& mesh, const Eigen::Vector3d& cor,
                                         const std::vector<std::int32_t>& faces, std::int64_t* edge_on = nullptr);

}  // namespace impinge
