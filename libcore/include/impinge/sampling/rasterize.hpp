#pragma once
/// @file rasterize.hpp
/// Sampling a mesh into a radial distance map by rasterisation (thesis sec. 3.2, Algorithm 1).

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "impinge/core/mesh.hpp"
#include "impinge/maps/radial_distance_map.hpp"
#include "impinge/sampling/raster_plan.hpp"
#include "impinge/schemes/equiangular_grid.hpp"
#include "impinge/core/enum_names.hpp"

namespace impinge {

/// How the distance at a covered node is computed.
enum class DistanceMode {
  /// The thesis' Algorithm 1: the vertices' distances interpolated linearly over the
  /// triangle in (theta, phi) (barycentric in the 2-D grid); triangles around a pole are split
  /// at the pole and interpolated over the trapezoid (theta, 0..phi) as in thesis Fig. 34.
  linear,
  /// The distance at which the node's ray meets the triangle's plane (exact for the mesh).
  exact,
};
/// The names of the distance modes (the option table's choices of --mode).
inline constexpr EnumNames<DistanceMode, 2> kDistanceModeNames{
    {{DistanceMode::exact, "exact"}, {DistanceMode::linear, "linear"}}};

/// Parse "linear" or "exact"; throws impinge::Error naming the value otherwise.
DistanceMode parse_distance_mode(const std::string& name, const std::string& context = "distance mode");
/// "linear" or "exact".
const char* to_string(DistanceMode mode);

/// Counts reported by a sampling run, so that nothing is dropped silently.
struct SamplingStats {
  std::int64_t triangles = 0;          ///< triangles in the mesh
  std::int64_t triangles_edge_on = 0;  ///< skipped: plane through the COR (covers no direction)
  std::int64_t triangles_culled = 0;   ///< skipped: can never be the nearest hit (raster_plan.hpp)
  std::int64_t pole_triangles = 0;     ///< triangles touching or containing a pole (cases 1-3)
  std::int64_t seam_triangles = 0;     ///< triangles crossing theta = 0/360
  std::int64_t node_tests = 0;         ///< node-in-triangle tests performed
  std::int64_t nodes_covered = 0;      ///< nodes this call gave a surface that had none before
                                       ///< (for a fresh map: all nodes with a surface)
};

/// What rasterize does with the values already in the map.
enum class MapStart {
  /// Keep them where they are nearer (several meshes can be sampled into one map).
  keep,
  /// Set every node to "no surface" first: a fresh map. With a plan in exact mode the reset is
  /// done in bands of rows, each just before the cones that start in it are drawn, so that
  /// their map lines are still in the cache (the same map as std::fill followed by drawing,
  /// and faster).
  reset,
};

/// How rasterize draws (one options struct instead of a positional tail).
struct RasterizeOptions {
  /// Exact mode only (ignored in linear mode): plan_rasterization's plan for this mesh and COR. Its
  /// cones are rasterised (set up once; the kept triangles when culling is enabled, about half of a
  /// closed mesh, else all), in its cache-friendly order. Null: every triangle, set up here.
  const RasterPlan* plan = nullptr;
  /// Exact mode: test only the columns of each row that the cone can cover (triangle_cone.hpp)
  /// instead of the whole box; the map is the same node for node (tested), so false is only the
  /// reference for that test.
  bool row_spans = true;
  /// Keep the map's values where they are nearer (the default) or reset the map first (MapStart).
  MapStart start = MapStart::keep;
};

/// Fill `map` with the nearest hit of every node's ray on `mesh` by rasterisation: each
/// triangle is projected into the (phi, theta) grid (its bounding rows and columns, with the
/// theta = 0/360 seam and the poles handled: the whole row range is taken when the triangle's
/// cone contains a pole), and every node in that box is tested against the triangle's cone with
/// three edge functions of the node's direction (watertight: nodes on a shared edge are covered
/// by both triangles). Where several triangles cover a node the smallest distance is kept
/// (the pelvis is not star-shaped from the COR). Nodes no triangle covers keep "no surface".
///
/// `mesh`: vertices in mm in the map's frame; `cor` (mm): origin of the spherical frame.
/// Cost O(triangles + nodes in the triangles' bounding boxes). `options`: RasterizeOptions (a plan,
/// row spans, whether the map starts fresh). Throws impinge::Error naming the mesh when the plan was
/// made for another mesh or COR (mesh_fingerprint), or the mesh is invalid (validate_mesh, checked
/// before the map is touched). The row kernels run in vectorised clones (AVX-512 / AVX2 chosen at run
/// time).
/// Source: thesis sec. 3.2, Algorithm 1, Fig. 33-34; culling, cones and spans: impinge (not in the thesis).
template <typename Scalar>
SamplingStats rasterize(const TriangleMesh& mesh, const Eigen::Vector3d& cor, DistanceMode mode,
                        RadialDistanceMapT<Scalar>& map, const RasterizeOptions& options = {});

/// One-shot convenience: a new float map of precision `precision_deg` sampled from `mesh`.
RadialDistanceMap rasterize_map(const TriangleMesh& mesh, const Eigen::Vector3d& cor, double precision_deg,
                                DistanceMode mode, SamplingStats* stats = nullptr);

}  // namespace impinge
