#pragma once
/// @file fcl_collision.hpp
/// FCL (the Flexible Collision Library, 0.7) as a peer: OBBRSS bounding-volume
/// trees, the successor of the thesis' RAPID OBB tree (sec. 2.2.1, Tables 4 and 9). Collision
/// per pose with every contact (triangle pair) reported, and the minimum distance per pose.
/// Built only when FCL is found (IMPINGE_HAVE_FCL); `have_fcl()` says which.

#include <Eigen/Core>
#include <cstdint>
#include <memory>

#include "impinge/core/mesh.hpp"

namespace impinge {

/// True when this build has FCL.
bool have_fcl();

/// Result of one FCL collision query.
struct FclContacts {
  std::int64_t contacts = 0;  ///< intersecting triangle pairs reported (all, up to the cap)
  bool capped = false;        ///< true when the cap (max_contacts) was reached
};

/// Ball and socket as two OBBRSS trees about a common COR, built once.
class FclJoint {
 public:
  /// Build both trees (vertices relative to `cor`, mm). Throws impinge::Error without FCL in
  /// this build or for an invalid mesh.
  FclJoint(const TriangleMesh& ball, const TriangleMesh& socket, const Eigen::Vector3d& cor);
  ~FclJoint();
  FclJoint(FclJoint&&) noexcept;
  FclJoint& operator=(FclJoint&&) noexcept;

  /// Collision with the ball rotated by R about the COR and translated by t (mm, socket frame),
  /// every contact (up to `max_contacts`) with its triangle pair; no contact points.
  FclContacts collide(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, std::int64_t max_contacts = 1000000) const;
  /// Minimum distance (mm) between the surfaces at that pose; negative is not reported by FCL
  /// for meshes (0 or -1 when they intersect, as FCL's DistanceResult gives).
  double distance(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace impinge
