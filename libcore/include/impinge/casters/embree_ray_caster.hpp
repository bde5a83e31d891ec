#pragma once
/// @file embree_ray_caster.hpp
/// Embree 3 as a peer: the fastest general ray caster, used as the baseline of the
/// radial look-up (cast the COR-to-vertex ray at the other bone) and of map filling (cast
/// every node's ray: the modern form of the thesis' pairwise O(m n) sampling, sec. 3.2).
/// Built only when Embree 3 is found (IMPINGE_HAVE_EMBREE); `have_embree()` says which.
/// Embree works in float: the mesh is translated so the origin (the COR) is at 0 first, which
/// keeps its coordinates below ~200 mm and the hit distance within ~2e-5 mm of the exact one.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "impinge/core/mesh.hpp"
#include "impinge/maps/radial_distance_map.hpp"

namespace impinge {

/// True when this build has Embree 3.
bool have_embree();

/// Throws the error of Embree's error code `rtc_error` (an RTCError: 1 unknown, 2 invalid argument, 3 invalid
/// operation, 4 out of memory, 5 unsupported CPU, 6 cancelled) met while `what` ("building the ray-casting hierarchy
/// of femur.ply (70422 triangles)"): OutOfMemory for RTC_ERROR_OUT_OF_MEMORY ("out of memory WHAT"), else Error
/// ("embree: WHAT failed (RTCError N: name)"). Source: impinge (issue 80: out of memory was told as an Embree failure).
[[noreturn]] void throw_embree_error(int rtc_error, const std::string& what);

/// How a ray caster's hierarchy is built. `quality`: Embree's default for a static scene (binned SAH; BVH8 where the
/// CPU has AVX-512), for many rays (filling maps, a motion's look-ups). `fast`: Morton codes into a BVH4 (Embree's
/// device configuration `tri_accel=bvh4.triangle4v,tri_builder=morton`), about 3x faster to build (lhdl-ct, one
/// thread: 5.7 against 16 ms for the femur's 70k triangles, 7.9 against 23 ms for the pelvis' 95k;
/// `impinge_bench --benchmark_filter=FirstHitCasterBuild`) and slower per ray, for the few rays of one pose. The
/// hits are the same either way (the same triangles intersected the same way; only the tree differs).
/// Source: impinge (issue 52: a set-up chosen by the work); Embree 3 API, rtcNewDevice's configuration.
enum class HierarchyBuild { quality, fast };

/// Embree scene of one mesh, for rays from a fixed origin (the COR). Single-threaded device
/// ("threads=1"): every figure of this project is single thread unless it says otherwise.
class EmbreeRayCaster {
 public:
  /// Build the scene (BVH) of `mesh` (mm) about `origin` (mm). `robust`: Embree's watertight
  /// mode (RTC_SCENE_FLAG_ROBUST), so that a ray through a shared vertex or edge cannot slip
  /// between the triangles (slower; leave out triangles edge-on to the origin first, whose hits it
  /// gets wrong); a robust scene also answers all_hits (RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION). `build`: the
  /// hierarchy's builder (HierarchyBuild). Throws impinge::Error when Embree is not in this build, the mesh is
  /// invalid, or Embree reports an error.
  EmbreeRayCaster(const TriangleMesh& mesh, const Eigen::Vector3d& origin, bool robust = false,
                  HierarchyBuild build = HierarchyBuild::quality);
  ~EmbreeRayCaster();
  EmbreeRayCaster(EmbreeRayCaster&&) noexcept;
  EmbreeRayCaster& operator=(EmbreeRayCaster&&) noexcept;

  /// Distance (mm) from the origin along direction (dx, dy, dz) (any nonzero length) to the
  /// nearest hit, +inf on a miss. One rtcIntersect1.
  float first_hit(float dx, float dy, float dz) const;
  /// The least first_hit of k <= 4 rays (dirs: k x 3, row-major, any nonzero lengths) in one
  /// rtcIntersect4 call: cheaper than k single rays when they are close together. `within` (mm): the
  /// rays end there (Embree's tfar), so a nearest hit beyond it is not sought and +inf is returned
  /// instead (a hit nearer than `within` is the same either way).
  float least_hit(const float* dirs, int k, float within = std::numeric_limits<float>::infinity()) const;

  /// Every hit of the ray from the origin along (dx, dy, dz) (any nonzero length), in one traversal
  /// (a context filter records each candidate and rejects it): appends (distance along the unit
  /// direction in mm, triangle index in the mesh given to the constructor) to `out`, unsorted; a ray
  /// through a shared edge may report both triangles. Throws impinge::Error on a scene built
  /// without `robust`. Source: impinge (layered maps; not in the thesis).
  void all_hits(float dx, float dy, float dz, std::vector<std::pair<float, unsigned>>& out) const;

  /// The radial scan through Embree, the peer of scan_gaps_compact (detection/detection.hpp, which
  /// has the ScanSet form scan_gaps_embree): for point j (x, y, z: n values each, mm, relative to the
  /// COR), q = R p_j + t, gap_mm[j] = side * (nearest hit along q - |q|) (side +1 or -1), NaN on a
  /// miss or at the COR. `packet8`: rtcIntersect8 on 8 rays at a time instead of rtcIntersect1 per ray.
  void scan_gaps(const double* x, const double* y, const double* z, std::int64_t n, const Eigen::Matrix3d& R,
                 const Eigen::Vector3d& t, double side, float* gap_mm, bool packet8) const;

  /// Fill `map` by casting every node's ray (nearest hit; +inf on a miss), in 8-ray packets.
  /// Returns the number of nodes with a surface.
  template <typename Scalar>
  std::int64_t fill_map(RadialDistanceMapT<Scalar>& map) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace impinge
